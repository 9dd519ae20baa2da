// The live scene on real GL nodes: an application sends 1,000 random
// transactions over 600 frames of the 2×2 power wall (through the C++
// client, paced by the frames it is told of). Every node keeps the master's
// state hash every frame; the stitched tiles of a captured frame equal the
// reference render-reference draws from the recorded journal (--replay);
// and the journal replayed with no application gives byte-identical
// captures. Label gpu (GL nodes, llvmpipe in CI).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <set>
#include <string>

#include "clients/cpp/session.h"
#include "cluster_run.h"
#include "image/compare.h"
#include "image/frame_files.h"
#include "image/image_io.h"
#include "local_capture.h"
#include "process.h"
#include "scratch.h"
#include "wall_session.h"

namespace optique::testing {
namespace {

using namespace std::chrono_literals;

const std::string kMaster = std::string(OPTIQUE_BIN_DIR) + "/optique-master";
const std::string kWall = std::string(OPTIQUE_SOURCE_DIR) + "/configs/powerwall-2x2.json";
constexpr int kFrames = 600;
constexpr int kTransactions = 1000;
constexpr int kCaptureEvery = 150;
constexpr std::uint64_t kCompared = 450;  // a captured frame well into the edits

// Random edits that the master should accept every one of: the application
// keeps its own copy of the tree (parents, so a removal takes the subtree and
// no re-parenting makes a cycle or a chain over the limit), and of the point
// lights it added (from index `first_light`, after the scene's own).
class RandomEdits {
 public:
  RandomEdits(std::uint32_t seed, std::uint32_t first_light) : random_(seed), first_light_(first_light) {}

  client::Transaction next() {
    client::Transaction t;
    const int edits = 1 + static_cast<int>(random_() % 4);
    for (int i = 0; i < edits; ++i) add_one(t);
    return t;
  }
  [[nodiscard]] std::size_t instances() const { return parent_.size(); }
  [[nodiscard]] std::size_t lights() const { return lights_.size(); }

 private:
  double uniform(double low, double high) { return std::uniform_real_distribution<double>(low, high)(random_); }

  client::Placement placement() {
    const double a = uniform(0.0, 6.283);
    return {{{uniform(-1.6, 1.6), uniform(-0.2, 1.6), uniform(-0.4, 0.4)}},
            {{std::cos(a / 2), 0.0, std::sin(a / 2), 0.0}},
            {{uniform(0.05, 0.3), uniform(0.05, 0.3), uniform(0.05, 0.3)}}};
  }

  std::string any() {
    auto it = parent_.begin();
    std::advance(it, static_cast<long>(random_() % parent_.size()));
    return it->first;
  }

  std::size_t depth(const std::string& id) const {
    std::size_t d = 0;
    for (std::string at = id; !at.empty(); at = parent_.at(at)) ++d;
    return d;
  }
  bool under(const std::string& id, const std::string& maybe_ancestor) const {
    for (std::string at = id; !at.empty(); at = parent_.at(at)) {
      if (at == maybe_ancestor) return true;
    }
    return false;
  }
  std::size_t height(const std::string& id) const {  // the deepest chain below it, it included
    std::size_t most = 1;
    for (const auto& [child, p] : parent_) {
      if (p == id) most = std::max(most, 1 + height(child));
    }
    return most;
  }

  void add_one(client::Transaction& t) {
    const unsigned kind = parent_.size() < 5 ? 0 : static_cast<unsigned>(random_() % 10);
    if (kind < 3) {  // create, under the world or another instance
      const std::string id = "n" + std::to_string(next_id_++);
      std::string parent;
      if (!parent_.empty() && random_() % 3 == 0) {
        parent = any();
        if (depth(parent) >= 8) parent.clear();
      }
      t.create(id, "cubes", placement(), parent, random_() % 8 == 0);
      parent_[id] = parent;
    } else if (kind < 6) {
      t.move(any(), placement());
    } else if (kind == 6) {
      const std::string id = any();
      std::string parent = random_() % 2 == 0 ? std::string() : any();
      if (!parent.empty() && (under(parent, id) || depth(parent) + height(id) > 12)) parent.clear();
      t.reparent(id, parent);
      parent_[id] = parent;
    } else if (kind == 7 && random_() % 3 == 0) {  // a point light added, moved, switched or removed
      // Two at most: each light costs llvmpipe every pixel of every frame.
      const std::uint32_t light = first_light_ + static_cast<std::uint32_t>(random_() % 2);
      if (lights_.count(light) == 0) {
        t.point_light(light, {{uniform(-1.6, 1.6), uniform(0.0, 1.6), uniform(0.2, 1.0)}},
                      {{uniform(0.0, 1.0), uniform(0.0, 1.0), uniform(0.0, 1.0)}}, uniform(0.1, 2.0));
        lights_.insert(light);
      } else if (random_() % 3 == 0) {
        t.remove_point_light(light);
        lights_.erase(light);
      } else if (random_() % 2 == 0) {
        t.switch_light(light, random_() % 2 == 0);
      } else {
        t.point_light(light, {{uniform(-1.6, 1.6), uniform(0.0, 1.6), uniform(0.2, 1.0)}});
      }
    } else if (kind == 7) {
      t.show(any(), random_() % 2 == 0);
    } else if (kind == 8 && random_() % 2 == 0) {
      t.tint(any(), {uniform(0.0, 1.0), uniform(0.0, 1.0), uniform(0.0, 1.0), 1.0});
    } else if (kind == 8) {  // its own animation clock: paused, played, sought
      const bool seek = random_() % 2 == 0;
      t.animate(any(), random_() % 2 == 0, seek ? std::optional<double>(uniform(0.0, 10.0)) : std::nullopt);
    } else {
      const std::string id = any();
      t.remove(id);
      std::set<std::string> gone{id};
      for (bool more = true; more;) {
        more = false;
        for (const auto& [child, p] : parent_) {
          if (gone.count(p) != 0 && gone.insert(child).second) more = true;
        }
      }
      for (const std::string& g : gone) parent_.erase(g);
    }
  }

  std::mt19937 random_;
  std::uint32_t first_light_;
  std::set<std::uint32_t> lights_;             // the point lights added
  std::map<std::string, std::string> parent_;  // every instance's parent ("" the world)
  int next_id_ = 0;
};

TEST(LiveSceneOnGlNodes, RandomTransactionsStayCoherentAndTheJournalDrawsTheSame) {
  ScratchDir dir("optique-live-gl");
  const std::string journal = dir.file("session.journal");
  const std::string live_out = dir.file("live");
  auto running = recording_wall(dir, kFrames, kCaptureEvery);
  Process& master = *running;
  auto session = wall_session(dir.file("api.port"), "coherence", master);
  ASSERT_NE(session, nullptr);
  client::Session& app = *session;

  // Two transactions a frame, from the first frame on, until all are sent.
  RandomEdits edits(31, app.scene().light_count());
  int sent = 0;
  int refused = 0;
  std::uint64_t last_frame = 0;
  while (sent < kTransactions) {
    auto event = app.next_event(30s);
    ASSERT_TRUE(event.ok() && event.value().has_value()) << "no frame event: " << master.output();
    if (!event.value()->has_frame_begun()) continue;
    for (int i = 0; i < 2 && sent < kTransactions; ++i, ++sent) {
      auto outcome = app.apply(edits.next());
      ASSERT_TRUE(outcome.ok()) << outcome.error();
      if (!outcome.value().applied()) {
        ++refused;
        ADD_FAILURE() << "refused: " << outcome.value().refused->field() << ": " << outcome.value().refused->reason();
      }
      last_frame = outcome.value().frame;
    }
  }
  app.close();
  std::printf("%d transactions applied by frame %llu, %zu instances and %zu point lights added then\n", sent - refused,
              static_cast<unsigned long long>(last_frame), edits.instances(), edits.lights());
  ASSERT_LT(last_frame, static_cast<std::uint64_t>(kFrames) - 10) << "the edits outlasted the run";
  expect_whole_run(master, live_out, kFrames);
  if (HasFatalFailure()) return;

  // The reference drawn from the journal against the stitched tiles.
  Process reference({kMaster, "render-reference", "--config", kWall, "--frame", std::to_string(kCompared), "--out",
                     dir.file("reference"), "--replay", journal},
                    dir.file("reference.log"));
  ASSERT_EQ(reference.wait(120s), 0) << reference.output();
  auto drawn = image::read_image(image::frame_path(dir.file("reference") + "/reference/front", kCompared, "png"));
  ASSERT_TRUE(drawn.ok()) << drawn.error();
  const image::FloatImage tiles = stitched_wall(live_out, kCompared);
  const double worst = expect_near_reference(tiles, drawn.value(), 40.0, "optique-live-gl-failure");
  std::printf("frame %llu, stitched tiles vs the journal's reference: PSNR %.1f dB (the worst channel)\n",
              static_cast<unsigned long long>(kCompared), worst);

  // The journal replayed with no application: the same captures, byte for
  // byte, up to the frame compared with the reference.
  const CapturedRun replayed =
      run_and_capture(kWall, static_cast<int>(kCompared) + 1, kCaptureEvery, {"--replay", journal});
  std::vector<std::uint64_t> captured;
  for (std::uint64_t frame = 0; frame <= kCompared; frame += kCaptureEvery) captured.push_back(frame);
  expect_same_captures(live_out, replayed.out, captured);
}

}  // namespace
}  // namespace optique::testing
