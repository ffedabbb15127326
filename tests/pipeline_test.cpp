// The pipeline as a library: what a plan needs and how often, parsing that builds nothing, progress
// reported to the sink in the options, cancellation leaving nothing behind, and the report value
// against the report.json it wrote.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "errors.h"
#include "pipeline/pipeline.h"
#include "tests/test_support.h"

namespace lacuna {
namespace {

namespace fs = std::filesystem;

using test::read_file;
using test::TempDir;

// Records the stages it is told about; asks to stop once `cancel_after` stages have begun (0: never).
class RecordingSink : public ProgressSink {
 public:
  explicit RecordingSink(size_t cancel_after = 0) : cancel_after_(cancel_after) {}
  void begin(const std::string& stage, uint64_t total) override {
    stages.push_back(stage);
    totals.push_back(total);
  }
  void advance(uint64_t n) override { done += n; }
  void end() override { ++ends; }
  bool cancelled() const override { return cancel_after_ > 0 && stages.size() >= cancel_after_; }

  std::vector<std::string> stages;
  std::vector<uint64_t> totals;
  std::atomic<uint64_t> done{0};
  size_t ends = 0;

 private:
  size_t cancel_after_;
};

const char* kBallRecipe = R"({
  "voxel_size_mm": 0.2,
  "inputs": {"ball": {"type": "sphere", "radius_mm": 2}},
  "outputs": [{"of": "ball", "file": "ball.stl"}]
})";


TEST(Pipeline, PlanNeedsWhatTheOutputsReadAndCountsEachRead) {
  const Recipe recipe = parse_recipe(R"({
    "inputs": {"a": {"type": "sphere", "radius_mm": 1}, "b": {"type": "sphere", "radius_mm": 1, "center_mm": [1, 0, 0]},
               "unused": {"type": "sphere", "radius_mm": 1}},
    "operations": [{"name": "u", "op": "union", "of": ["a", "b"]}, {"name": "s", "op": "shell", "of": "u", "thickness_mm": 0.2}],
    "outputs": [{"of": "s", "file": "s.stl"}, {"of": "u", "file": "u.stl"}, {"of": "s", "file": "s.3mf"}]
  })", "plan.json");
  const Plan p = plan(recipe);
  EXPECT_EQ(p.inputs, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(p.operations, (std::vector<std::string>{"u", "s"}));
  EXPECT_EQ(p.exported, (std::vector<std::string>{"s", "u"}));  // each object meshed once, first named first
  // u is read by s and meshed once; s is meshed once for both of its files.
  EXPECT_EQ(p.uses, (std::map<std::string, int>{{"a", 1}, {"b", 1}, {"u", 2}, {"s", 1}}));
  EXPECT_EQ(p.needed.count("unused"), 0u);
}

TEST(Pipeline, ParsingBuildsNothing) {
  // 20^9 Menger cubes: reading the recipe only records the level; building refuses it from the count.
  const Recipe recipe = parse_recipe(R"({
    "inputs": {"s": {"type": "cifs", "system": "menger_sponge", "level": 9}},
    "outputs": [{"of": "s", "file": "s.stl"}]
  })", "sponge.json");
  ASSERT_EQ(recipe.inputs.size(), 1u);
  ASSERT_TRUE(std::holds_alternative<CifsInput>(recipe.inputs[0].spec));
  EXPECT_EQ(std::get<CifsInput>(recipe.inputs[0].spec).level, 9);
  try {
    build_inputs(recipe);
    FAIL() << "level 9 was built";
  } catch (const ResourceLimit& e) {
    EXPECT_NE(std::string(e.what()).find("sponge.json: inputs.s: level 9 has 512000000000 pieces"), std::string::npos)
        << e.what();
  }
}

TEST(Pipeline, RunReportsEveryStageToTheSinkAndTheReportIsTheFileWritten) {
  TempDir dir;
  std::ofstream(dir.path() / "ball.json") << kBallRecipe;
  RecordingSink sink;
  RunOptions options;
  options.output_dir = (dir.path() / "out").string();
  options.progress = &sink;
  const RunReport report = run((dir.path() / "ball.json").string(), options);
  ASSERT_TRUE(report.valid);
  ASSERT_EQ(report.outputs.size(), 1u);
  EXPECT_TRUE(report.outputs[0].valid());
  EXPECT_EQ(report.written, (std::vector<std::string>{(dir.path() / "out" / "ball.stl").string(),
                                                      (dir.path() / "out" / "report.html").string(),
                                                      (dir.path() / "out" / "report.json").string()}));
  // Every stage that began ended; the sphere was rasterized, meshed and its file checked.
  EXPECT_EQ(sink.ends, sink.stages.size());
  for (const char* stage : {"rasterize", "mesh", "check"})
    EXPECT_NE(std::find(sink.stages.begin(), sink.stages.end(), stage), sink.stages.end()) << stage;
  EXPECT_GT(sink.done.load(), 0u);
  EXPECT_EQ(to_json(report), nlohmann::json::parse(read_file(dir.path() / "out" / "report.json")));
}

TEST(Pipeline, CancelledRunThrowsAndLeavesNothing) {
  TempDir dir;
  std::ofstream(dir.path() / "ball.json") << kBallRecipe;
  RecordingSink sink(1);  // stop once the first stage has begun
  RunOptions options;
  options.output_dir = (dir.path() / "out").string();
  options.progress = &sink;
  EXPECT_THROW(run((dir.path() / "ball.json").string(), options), Cancelled);
  EXPECT_EQ(sink.stages.size(), 1u);
  EXPECT_EQ(sink.ends, 1u);
  EXPECT_FALSE(fs::exists(dir.path() / "out"));
}

// Asks to stop as soon as a stage reports its first step, from whichever thread reports it.
class StopAtFirstStep : public ProgressSink {
 public:
  void begin(const std::string&, uint64_t) override {
    ++begun;
    began_after_stop = began_after_stop || done.load() > 0;
  }
  void advance(uint64_t n) override { done += n; }
  void end() override { ++ends; }
  bool cancelled() const override { return done.load() > 0; }

  std::atomic<uint64_t> done{0};
  size_t begun = 0, ends = 0;
  bool began_after_stop = false;
};

TEST(Pipeline, CancellationStopsInsideAStage) {
  TempDir dir;
  std::ofstream(dir.path() / "ball.json") << kBallRecipe;
  StopAtFirstStep sink;
  RunOptions options;
  options.output_dir = (dir.path() / "out").string();
  options.progress = &sink;
  EXPECT_THROW(run((dir.path() / "ball.json").string(), options), Cancelled);
  EXPECT_GT(sink.done.load(), 0u);
  EXPECT_FALSE(sink.began_after_stop);  // stopped within the stage that reported the step
  EXPECT_EQ(sink.ends, sink.begun);
  EXPECT_FALSE(fs::exists(dir.path() / "out"));
}

}  // namespace
}  // namespace lacuna
