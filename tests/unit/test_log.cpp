// The logger main makes (log::make_logger, the one the master, the node and the
// tools use): a message carrying a newline, an ESC sequence or bytes that are not
// UTF-8 (a node id from an unauthenticated hello, say) comes out as one line of
// escapes in every sink, those added or given another pattern afterwards (as the
// master's CLI does for its status line and the operator page's warnings) too.

#include "log/logger.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <stdlib.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "log/escape.h"
#include "scratch.h"

namespace optique::log {
namespace {

namespace fs = std::filesystem;

const std::string kHostile = "node 'evil\nFAKE [error] line' \x1b[31mred\x1b[0m";
const std::string kEscaped = "node 'evil\\nFAKE [error] line' \\x1b[31mred\\x1b[0m";

TEST(Log, EveryControlCharacterAndInvalidUtf8IsEscaped) {
  EXPECT_EQ(escape_for_log(kHostile), kEscaped);
  EXPECT_EQ(escape_for_log("a\rb\tc\x7f"
                           "d"),
            "a\\rb\\tc\\x7fd");
  EXPECT_EQ(escape_for_log(std::string("nul\0x", 5)), "nul\\x00x");
  EXPECT_EQ(escape_for_log("c1 \xc2\x9b"
                           "31m"),
            "c1 \\u009b31m")
      << "C1 CSI, encoded as UTF-8";
  EXPECT_EQ(escape_for_log("raw \x9b"
                           "31m"),
            "raw \\x9b31m")
      << "C1 as a lone byte: not UTF-8";
  EXPECT_EQ(escape_for_log("over \xc0\x8a long"), "over \\xc0\\x8a long") << "an overlong newline";
  EXPECT_EQ(escape_for_log("cut \xe2\x82"), "cut \\xe2\\x82");
  EXPECT_EQ(escape_for_log("sep \xe2\x80\xa8 rtl \xe2\x80\xae"), "sep \\u2028 rtl \\u202e");
  EXPECT_EQ(escape_for_log("Grüße, 東京, 🎥, \\n"), "Grüße, 東京, 🎥, \\n") << "UTF-8 and backslashes stay";
  EXPECT_FALSE(needs_escaping("plain text [info] 12:00"));
  EXPECT_TRUE(needs_escaping("ü"));
}

class LoggerTest : public ::testing::Test {
 protected:
  static std::string read(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  optique::testing::ScratchDir scratch_{"optique-log"};
  fs::path dir_ = scratch_.path();
};

TEST_F(LoggerTest, AHostileMessageIsOneLineOfEscapesInEverySink) {
  const fs::path file = dir_ / "master.log";
  auto logger = make_logger("master", "info", file.string());
  // As the master's CLI does: another pattern for stderr, and a sink added later.
  logger->sinks().front()->set_pattern("\r\033[K%H:%M:%S.%e %^%-5l%$ [%n] %v");
  std::ostringstream later;
  logger->sinks().push_back(std::make_shared<spdlog::sinks::ostream_sink_mt>(later));
  logger->warn("refused {}", kHostile);
  logger->info("plain");
  logger->flush();

  const std::string written = read(file);
  EXPECT_EQ(std::count(written.begin(), written.end(), '\n'), 2) << written;
  EXPECT_EQ(written.find('\x1b'), std::string::npos) << written;
  EXPECT_NE(written.find("[master] refused " + kEscaped + "\n"), std::string::npos) << written;
  EXPECT_NE(written.find("[master] plain\n"), std::string::npos) << written;
  const std::string added = later.str();
  EXPECT_EQ(std::count(added.begin(), added.end(), '\n'), 2) << added;
  EXPECT_NE(added.find("refused " + kEscaped + "\n"), std::string::npos) << added;
}

TEST_F(LoggerTest, StderrGetsTheEscapesToo) {
  // The pattern's own colours and the status line's \r\033[K are the program's,
  // not the message's: only those reach the terminal.
  const fs::path captured = dir_ / "stderr";
  fflush(stderr);
  const int saved = dup(STDERR_FILENO);
  FILE* into = fopen(captured.c_str(), "w");
  ASSERT_NE(into, nullptr);
  dup2(fileno(into), STDERR_FILENO);
  {
    auto logger = make_logger("node wall", "info");
    logger->error("goodbye: {}", kHostile);
    logger->flush();
  }
  fflush(stderr);
  dup2(saved, STDERR_FILENO);
  close(saved);
  fclose(into);
  const std::string written = read(captured);
  EXPECT_EQ(std::count(written.begin(), written.end(), '\n'), 1) << written;
  EXPECT_NE(written.find("goodbye: " + kEscaped), std::string::npos) << written;
  EXPECT_EQ(written.find("\x1b[31mred"), std::string::npos) << written;
}

TEST_F(LoggerTest, AClonedLoggerEscapesToo) {
  const fs::path file = dir_ / "clone.log";
  auto logger = make_logger("tools", "info", file.string());
  auto cloned = logger->clone("compose");
  cloned->warn("{}", kHostile);
  cloned->flush();
  const std::string written = read(file);
  EXPECT_NE(written.find("[compose] " + kEscaped + "\n"), std::string::npos) << written;
}

}  // namespace
}  // namespace optique::log
