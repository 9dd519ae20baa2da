// Writes the seed corpus: optique-fuzz-corpus DIR fills DIR/frames, DIR/deltas,
// DIR/protocol, DIR/node and DIR/tracker (tests/fuzz/corpus is the committed one). Files already there and not seeds,
// e.g. crash inputs kept as regressions, are left alone.

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "fuzz_seeds.h"

namespace {

bool write_all(const std::filesystem::path& dir, const std::vector<optique::fuzz::Seed>& seeds) {
  std::filesystem::create_directories(dir);
  for (const auto& seed : seeds) {
    std::ofstream out(dir / seed.name, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(seed.bytes.data()), static_cast<std::streamsize>(seed.bytes.size()));
    if (!out) {
      std::fprintf(stderr, "optique-fuzz-corpus: cannot write %s\n", (dir / seed.name).c_str());
      return false;
    }
  }
  std::printf("%zu seeds in %s\n", seeds.size(), dir.c_str());
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: optique-fuzz-corpus DIR   (e.g. tests/fuzz/corpus)\n");
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  const bool ok = write_all(dir / "frames", optique::fuzz::frame_seeds()) &&
                  write_all(dir / "deltas", optique::fuzz::delta_seeds()) &&
                  write_all(dir / "protocol", optique::fuzz::protocol_seeds()) &&
                  write_all(dir / "node", optique::fuzz::node_seeds()) &&
                  write_all(dir / "tracker", optique::fuzz::tracker_seeds()) &&
                  write_all(dir / "session", optique::fuzz::session_seeds());
  return ok ? 0 : 1;
}
