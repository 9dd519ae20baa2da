// The package as a render host gets it: `cmake --install` to a prefix, the
// Debian package (cpack -G DEB), its contents listed, its programs run from an
// extracted copy (a real --local run, GL nodes and all), and its systemd units
// accepted by systemd-analyze verify.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "cluster_run.h"
#include "process.h"

namespace optique::testing {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;

const std::string kBuild = OPTIQUE_BUILD_DIR;

// Runs `argv`; its status, its output in `log`.
int run(const std::vector<std::string>& argv, const std::string& log, std::chrono::seconds timeout = 120s) {
  Process process(argv, log);
  return process.wait(timeout).value_or(-1);
}

TEST(Package, CmakeInstallPutsTheProgramsConfigsAndDocsUnderThePrefix) {
  const ScratchDir dir_scratch("optique-install");
  const std::string dir = dir_scratch.string();
  const std::string prefix = dir + "/prefix";
  ASSERT_EQ(run({"/usr/bin/cmake", "--install", kBuild, "--prefix", prefix}, dir + "/install.log"), 0)
      << read_file(dir + "/install.log");
  for (const char* program : {"optique-master", "optique-node", "optique-node-gl", "optique-tools"}) {
    EXPECT_TRUE(fs::exists(prefix + "/bin/" + program)) << program;
  }
  EXPECT_TRUE(fs::exists(prefix + "/share/optique/configs/cave-tracked.json"));
  EXPECT_TRUE(fs::exists(prefix + "/share/optique/configs/assets/head-walk.csv")) << "configs keep their assets";
  EXPECT_TRUE(fs::exists(prefix + "/share/doc/optique/README.md"));
  EXPECT_TRUE(fs::exists(prefix + "/share/doc/optique/docs/deploying.md")) << "the README's guides beside it";
  EXPECT_FALSE(fs::exists(prefix + "/lib/systemd")) << "the units only with --component service";
  // The installed master runs the installed tools.
  const std::string log = dir + "/check.log";
  EXPECT_EQ(
      run({prefix + "/bin/optique-master", "check-config", prefix + "/share/optique/configs/cave-tracked.json"}, log),
      0)
      << read_file(log);
  EXPECT_NE(read_file(log).find("tracking: replay of"), std::string::npos) << read_file(log);
}

// The service component follows the prefix: under /usr/local the units go to
// /usr/local/lib/systemd/system (where systemd looks), run the programs of that
// prefix and read <prefix>/etc/optique; with prefix /usr they are the package's,
// /etc/optique and all, staged under DESTDIR.
TEST(Package, TheServiceComponentFollowsThePrefix) {
  const ScratchDir dir_scratch("optique-service");
  const std::string dir = dir_scratch.string();
  const std::string prefix = dir + "/local";
  ASSERT_EQ(
      run({"/usr/bin/cmake", "--install", kBuild, "--prefix", prefix, "--component", "service"}, dir + "/local.log"), 0)
      << read_file(dir + "/local.log");
  const std::string master = read_file(prefix + "/lib/systemd/system/optique-master.service");
  EXPECT_NE(master.find("\nExecStart=" + prefix + "/bin/optique-master "), std::string::npos) << master;
  EXPECT_NE(master.find("\nEnvironmentFile=" + prefix + "/etc/optique/master.env\n"), std::string::npos) << master;
  EXPECT_EQ(master.find("/usr/bin"), std::string::npos) << master;
  const std::string node = read_file(prefix + "/lib/systemd/system/optique-node@.service");
  EXPECT_NE(node.find("--secret-file " + prefix + "/etc/optique/secret "), std::string::npos) << node;
  EXPECT_NE(read_file(prefix + "/etc/optique/master.env").find("OPTIQUE_CONFIG=" + prefix + "/etc/optique/"),
            std::string::npos);
  const std::string staged = dir + "/stage";
  ASSERT_EQ(run({"/usr/bin/env", "DESTDIR=" + staged, "/usr/bin/cmake", "--install", kBuild, "--prefix", "/usr",
                 "--component", "service"},
                dir + "/staged.log"),
            0)
      << read_file(dir + "/staged.log");
  EXPECT_EQ(read_file(staged + "/usr/lib/systemd/system/optique-master.service"),
            read_file(std::string(OPTIQUE_SOURCE_DIR) + "/packaging/systemd/optique-master.service"));
  EXPECT_TRUE(fs::exists(staged + "/usr/lib/systemd/system/optique-node@.service"));
  EXPECT_TRUE(fs::exists(staged + "/etc/optique/node.env"));
}

TEST(Package, TheDebianPackageHoldsEverythingAndRunsFromAnExtractedCopy) {
  const ScratchDir dir_scratch("optique-deb");
  const std::string dir = dir_scratch.string();
  ASSERT_EQ(run({"/usr/bin/cpack", "--config", kBuild + "/CPackConfig.cmake", "-G", "DEB", "-B", dir + "/out"},
                dir + "/cpack.log", 240s),
            0)
      << read_file(dir + "/cpack.log");
  std::string deb;
  for (const auto& entry : fs::directory_iterator(dir + "/out")) {
    if (entry.path().extension() == ".deb") deb = entry.path().string();
  }
  ASSERT_FALSE(deb.empty()) << read_file(dir + "/cpack.log");
  std::cout << "package: " << deb << ", " << fs::file_size(deb) / 1024 << " KiB\n";

  // Its contents and its control fields.
  ASSERT_EQ(run({"/usr/bin/dpkg-deb", "--contents", deb}, dir + "/contents.txt"), 0);
  const std::string contents = read_file(dir + "/contents.txt");
  for (const char* path :
       {"./usr/bin/optique-master", "./usr/bin/optique-node", "./usr/bin/optique-node-gl", "./usr/bin/optique-tools",
        "./usr/share/optique/configs/powerwall-2x2.json", "./usr/share/doc/optique/README.md",
        "./usr/share/doc/optique/docs/deploying.md", "./usr/lib/systemd/system/optique-master.service",
        "./usr/lib/systemd/system/optique-node@.service", "./etc/optique/master.env", "./etc/optique/node.env"}) {
    EXPECT_NE(contents.find(std::string(path) + "\n"), std::string::npos) << path << " not in\n" << contents;
  }
  ASSERT_EQ(run({"/usr/bin/dpkg-deb", "--field", deb, "Depends"}, dir + "/depends.txt"), 0);
  const std::string depends = read_file(dir + "/depends.txt");
  for (const char* package : {"adduser", "libprotobuf", "libspdlog", "libopenimageio", "libepoxy0", "libglfw3"}) {
    EXPECT_NE(depends.find(package), std::string::npos) << package << " not in: " << depends;
  }
  ASSERT_EQ(run({"/usr/bin/dpkg-deb", "--info", deb, "conffiles"}, dir + "/conffiles.txt"), 0);
  EXPECT_EQ(read_file(dir + "/conffiles.txt"), "/etc/optique/master.env\n/etc/optique/node.env\n")
      << "an operator's edits survive an upgrade";

  // The programs, from an extracted copy: a short --local run with GL nodes.
  const std::string root = dir + "/root";
  ASSERT_EQ(run({"/usr/bin/dpkg-deb", "-x", deb, root}, dir + "/extract.log"), 0) << read_file(dir + "/extract.log");
  const std::string master_log = dir + "/master.log";
  ASSERT_EQ(run({root + "/usr/bin/optique-master", "--config", root + "/usr/share/optique/configs/single-wall.json",
                 "--local", "--frames", "30", "--out", dir + "/run", "--no-status"},
                master_log),
            0)
      << read_file(master_log);
  const ClusterRun result = read_cluster_run(dir + "/run");
  ASSERT_TRUE(result.error.empty()) << result.error;
  EXPECT_EQ(result.report.frames(), 30u);
  EXPECT_EQ(result.report.nodes(0).frames_presented(), 30u);
  const std::string node_log = read_file(dir + "/run/logs/wall.log");
  EXPECT_NE(node_log.find("rendering builtin cubes with"), std::string::npos) << "the GL node drew: " << node_log;

  // systemd reads the units as it would on the host: with the system's own
  // units beside them (targets, default dependencies) under a root that has
  // the extracted programs at /usr/bin.
  const std::string units = root + "/usr/lib/systemd/system";
  fs::create_directories(units);
  for (const auto& entry : fs::directory_iterator("/lib/systemd/system")) {
    if (entry.is_regular_file() && !fs::exists(units / entry.path().filename())) {
      fs::copy_file(entry.path(), units / entry.path().filename());
    }
  }
  const std::string verify_log = dir + "/verify.log";
  EXPECT_EQ(run({"/usr/bin/systemd-analyze", "verify", "--man=no", "--root=" + root, "optique-master.service",
                 "optique-node@left.service"},
                verify_log),
            0)
      << read_file(verify_log);
  EXPECT_EQ(read_file(verify_log), "") << "no warning either";
}

}  // namespace
}  // namespace optique::testing
