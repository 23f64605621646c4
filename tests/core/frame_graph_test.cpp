#include "relight/core/frame_graph.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <ctime>

#include "relight/core/image.h"

namespace relight {
namespace {

// A source that writes a depth map whose every pixel equals the frame index + 1, and stops after
// `frames` frames.
class CountingSource final : public Stage {
 public:
  explicit CountingSource(int frames, std::string name = "source") : frames_(frames), name_(std::move(name)) {}
  std::string name() const override { return name_; }
  bool has_side_effects() const override { return true; }
  void declare(StageBuilder& b) override { depth_ = b.write<DepthMap>("depth"); }
  void run(StageContext& ctx) override {
    if (ctx.frame_index() >= frames_) return ctx.end_of_stream();
    auto& depth = ctx.get(depth_);
    depth.resize(4, 3);
    depth.fill(static_cast<float>(ctx.frame_index() + 1));
  }

 private:
  int frames_;
  std::string name_;
  Write<DepthMap> depth_;
};

// Doubles the depth and remembers the previous frame's doubled value it saw.
class Doubler final : public Stage {
 public:
  std::string name() const override { return "doubler"; }
  void declare(StageBuilder& b) override {
    in_ = b.read<DepthMap>("depth");
    out_ = b.write<DepthMap>("doubled");
    previous_ = b.read_previous<DepthMap>("doubled");
  }
  void run(StageContext& ctx) override {
    const auto& in = ctx.get(in_);
    const DepthMap* previous = ctx.get(previous_);
    seen_previous.push_back(previous ? (*previous)(0, 0) : -1.f);
    auto& out = ctx.get(out_);
    out.resize(in.width(), in.height());
    for (std::size_t i = 0; i < in.size(); ++i) out.pixels()[i] = 2.f * in.pixels()[i];
  }
  std::vector<float> seen_previous;

 private:
  Read<DepthMap> in_;
  Write<DepthMap> out_;
  ReadPrevious<DepthMap> previous_;
};

// Generic stage for validation tests: reads/writes the listed buffers as DepthMap or NormalMap.
class Wiring final : public Stage {
 public:
  Wiring(std::string name, std::vector<std::string> reads, std::vector<std::string> writes, bool normals = false)
      : name_(std::move(name)), reads_(std::move(reads)), writes_(std::move(writes)), normals_(normals) {}
  std::string name() const override { return name_; }
  bool has_side_effects() const override { return true; }
  void declare(StageBuilder& b) override {
    for (const auto& r : reads_) normals_ ? (void)b.read<NormalMap>(r) : (void)b.read<DepthMap>(r);
    for (const auto& w : writes_) (void)b.write<DepthMap>(w);
  }
  void run(StageContext&) override {}

 private:
  std::string name_;
  std::vector<std::string> reads_, writes_;
  bool normals_;
};

std::string compile_error(FrameGraph& graph) {
  try {
    graph.compile();
  } catch (const GraphError& e) {
    return e.what();
  }
  return "";
}

TEST(FrameGraph, RunsStagesInDependencyOrderRegardlessOfInsertionOrder) {
  FrameGraph graph;
  graph.emplace<Wiring>("late", std::vector<std::string>{"b"}, std::vector<std::string>{});
  graph.emplace<Wiring>("middle", std::vector<std::string>{"a"}, std::vector<std::string>{"b"});
  graph.emplace<Wiring>("early", std::vector<std::string>{}, std::vector<std::string>{"a"});
  graph.compile();
  EXPECT_EQ(graph.execution_order(), (std::vector<std::string>{"early", "middle", "late"}));
}

TEST(FrameGraph, MissingProducerNamesStageAndBuffer) {
  FrameGraph graph;
  graph.emplace<Wiring>("normals", std::vector<std::string>{"depth"}, std::vector<std::string>{});
  const std::string message = compile_error(graph);
  EXPECT_NE(message.find("'normals'"), std::string::npos) << message;
  EXPECT_NE(message.find("'depth'"), std::string::npos) << message;
  EXPECT_NE(message.find("no stage writes it"), std::string::npos) << message;
}

TEST(FrameGraph, TwoProducersAreRejected) {
  FrameGraph graph;
  graph.emplace<Wiring>("a", std::vector<std::string>{}, std::vector<std::string>{"depth"});
  graph.emplace<Wiring>("b", std::vector<std::string>{}, std::vector<std::string>{"depth"});
  const std::string message = compile_error(graph);
  EXPECT_NE(message.find("written by both stage 'a' and stage 'b'"), std::string::npos) << message;
}

TEST(FrameGraph, TypeMismatchNamesBothTypes) {
  FrameGraph graph;
  graph.emplace<Wiring>("src", std::vector<std::string>{}, std::vector<std::string>{"depth"});
  graph.emplace<Wiring>("reader", std::vector<std::string>{"depth"}, std::vector<std::string>{}, /*normals=*/true);
  const std::string message = compile_error(graph);
  EXPECT_NE(message.find("as NormalMap"), std::string::npos) << message;
  EXPECT_NE(message.find("writes it as DepthMap"), std::string::npos) << message;
  EXPECT_NE(message.find("'reader'"), std::string::npos) << message;
}

TEST(FrameGraph, CycleIsRejectedWithItsMembers) {
  FrameGraph graph;
  graph.emplace<Wiring>("src", std::vector<std::string>{}, std::vector<std::string>{"x"});
  graph.emplace<Wiring>("p", std::vector<std::string>{"x", "r"}, std::vector<std::string>{"q"});
  graph.emplace<Wiring>("s", std::vector<std::string>{"q"}, std::vector<std::string>{"r"});
  const std::string message = compile_error(graph);
  EXPECT_NE(message.find("cycle"), std::string::npos) << message;
  EXPECT_NE(message.find("'p'"), std::string::npos) << message;
  EXPECT_NE(message.find("'s'"), std::string::npos) << message;
  EXPECT_EQ(message.find("'src'"), std::string::npos) << message;
}

TEST(FrameGraph, DuplicateStageNamesAreRejected) {
  FrameGraph graph;
  graph.emplace<CountingSource>(1);
  EXPECT_THROW(graph.emplace<CountingSource>(1), GraphError);
}

TEST(FrameGraph, HistoryGivesPreviousFrameAndNullOnFirstFrame) {
  FrameGraph graph;
  graph.emplace<CountingSource>(3);
  auto& doubler = graph.emplace<Doubler>();
  graph.keep("doubled");
  int frames = 0;
  while (graph.run_frame()) {
    ++frames;
    const DepthMap* doubled = graph.find<DepthMap>("doubled");
    ASSERT_NE(doubled, nullptr);
    EXPECT_FLOAT_EQ((*doubled)(2, 3), 2.f * static_cast<float>(frames));
  }
  EXPECT_EQ(frames, 3);
  EXPECT_EQ(graph.frames_run(), 3);
  EXPECT_EQ(doubler.seen_previous, (std::vector<float>{-1.f, 2.f, 4.f}));
}

TEST(FrameGraph, ReadingOwnPreviousOutputIsNotACycle) {
  FrameGraph graph;
  graph.emplace<CountingSource>(2);
  graph.emplace<Doubler>();
  graph.keep("doubled");
  EXPECT_NO_THROW(graph.compile());
}

TEST(FrameGraph, UnusedStagesWithoutSideEffectsAreCulled) {
  FrameGraph graph;
  graph.emplace<CountingSource>(1);
  graph.emplace<Doubler>();  // nobody reads "doubled" and it is not kept
  graph.compile();
  EXPECT_EQ(graph.culled_stages(), std::vector<std::string>{"doubler"});
  EXPECT_EQ(graph.execution_order(), std::vector<std::string>{"source"});
  EXPECT_TRUE(graph.run_frame());
  EXPECT_EQ(graph.find<DepthMap>("doubled"), nullptr);
}

TEST(FrameGraph, TimesEveryStageEveryFrame) {
  FrameGraph graph;
  graph.emplace<CountingSource>(4);
  graph.emplace<Doubler>();
  graph.keep("doubled");
  while (graph.run_frame()) {
  }
  ASSERT_EQ(graph.timings().size(), 2u);
  for (const auto& timing : graph.timings()) {
    EXPECT_EQ(timing.wall_ms.size(), 4u) << timing.stage;
    for (double ms : timing.wall_ms) EXPECT_GE(ms, 0.0);
    EXPECT_EQ(timing.cpu_ms.size(), 4u) << timing.stage;
    for (double ms : timing.cpu_ms) EXPECT_GE(ms, 0.0);
  }
}

// Works on the calling thread until the process has spent `cpu_ms` more of CPU time.
class CpuBurner final : public Stage {
 public:
  explicit CpuBurner(double cpu_ms) : cpu_ms_(cpu_ms) {}
  std::string name() const override { return "burner"; }
  bool has_side_effects() const override { return true; }
  void declare(StageBuilder& b) override { in_ = b.read<DepthMap>("depth"); }
  void run(StageContext&) override {
    const std::clock_t start = std::clock();
    volatile double sink = 0.0;
    while (static_cast<double>(std::clock() - start) * 1000.0 / CLOCKS_PER_SEC < cpu_ms_) sink = sink + 1.0;
  }

 private:
  double cpu_ms_;
  Read<DepthMap> in_;
};

TEST(FrameGraph, CountsTheCpuTimeEachStageSpends) {
  FrameGraph graph;
  graph.emplace<CountingSource>(2);
  graph.emplace<CpuBurner>(30.0);
  while (graph.run_frame()) {
  }
  const StageTimings& burner = graph.timings().at(1);
  ASSERT_EQ(burner.stage, "burner");
  ASSERT_EQ(burner.cpu_ms.size(), 2u);
  // At least what it burnt (the process's CPU time, so other threads can only add to it); the
  // source, which does next to nothing, far less.
  for (double ms : burner.cpu_ms) EXPECT_GE(ms, 29.0);
  for (double ms : graph.timings().at(0).cpu_ms) EXPECT_LT(ms, 29.0);
}

class FinishCounter final : public Stage {
 public:
  explicit FinishCounter(int& finished) : finished_(finished) {}
  std::string name() const override { return "finish_counter"; }
  bool has_side_effects() const override { return true; }
  void declare(StageBuilder& b) override { in_ = b.read<DepthMap>("depth"); }
  void run(StageContext&) override { ++frames; }
  void finish() override { ++finished_; }
  int frames = 0;

 private:
  int& finished_;
  Read<DepthMap> in_;
};

TEST(FrameGraph, FinishReachesEveryStageOnceAfterTheLastFrame) {
  int finished = 0;
  FrameGraph graph;
  graph.emplace<CountingSource>(2);
  auto& counter = graph.emplace<FinishCounter>(finished);
  while (graph.run_frame()) {
  }
  EXPECT_EQ(finished, 0);
  graph.finish();
  EXPECT_EQ(finished, 1);
  EXPECT_EQ(counter.frames, 2);
}

TEST(FrameGraph, FindChecksTheType) {
  FrameGraph graph;
  graph.emplace<CountingSource>(1);
  ASSERT_TRUE(graph.run_frame());
  EXPECT_NE(graph.find<DepthMap>("depth"), nullptr);
  EXPECT_EQ(graph.find<NormalMap>("depth"), nullptr);
  EXPECT_EQ(graph.find<DepthMap>("nonexistent"), nullptr);
}

TEST(FrameGraph, DotListsStagesBuffersAndHistoryEdges) {
  FrameGraph graph;
  graph.emplace<CountingSource>(1);
  graph.emplace<Doubler>();
  graph.keep("doubled");
  graph.compile();
  const std::string dot = graph.to_dot();
  EXPECT_EQ(dot.rfind("digraph relight {", 0), 0u);
  EXPECT_NE(dot.find("\"stage:source\" -> \"buffer:depth\""), std::string::npos) << dot;
  EXPECT_NE(dot.find("\"buffer:depth\" -> \"stage:doubler\""), std::string::npos) << dot;
  EXPECT_NE(dot.find("style=dashed"), std::string::npos) << dot;
  EXPECT_EQ(std::count(dot.begin(), dot.end(), '{'), std::count(dot.begin(), dot.end(), '}'));
}

// A fake device that keeps bytes in host memory and counts transfers, to check that the graph
// moves data only when the other side is newer.
class FakeDeviceBuffer final : public DeviceBuffer {
 public:
  explicit FakeDeviceBuffer(std::size_t n) : bytes(n) {}
  std::size_t size_bytes() const override { return bytes.size(); }
  std::vector<std::byte> bytes;
};
class FakeDevice final : public DeviceTransfer {
 public:
  std::unique_ptr<DeviceBuffer> allocate(std::size_t n) override {
    ++allocations;
    return std::make_unique<FakeDeviceBuffer>(n);
  }
  void upload(std::span<const std::byte> src, DeviceBuffer& dst) override {
    ++uploads;
    std::copy(src.begin(), src.end(), static_cast<FakeDeviceBuffer&>(dst).bytes.begin());
  }
  void download(const DeviceBuffer& src, std::span<std::byte> dst) override {
    ++downloads;
    const auto& bytes = static_cast<const FakeDeviceBuffer&>(src).bytes;
    std::copy(bytes.begin(), bytes.end(), dst.begin());
  }
  int uploads = 0;
  int downloads = 0;
  int allocations = 0;
};

// "Vulkan" stage that adds 10 to every depth value on the fake device.
class DeviceAddTen final : public Stage {
 public:
  DeviceAddTen(std::string input = "depth", std::string output = "plus_ten", std::string name = "device_add_ten")
      : input_(std::move(input)), output_(std::move(output)), name_(std::move(name)) {}
  std::string name() const override { return name_; }
  Backend backend() const override { return Backend::Vulkan; }
  void declare(StageBuilder& b) override {
    in_ = b.read<DepthMap>(input_);
    out_ = b.write<DepthMap>(output_);
  }
  void run(StageContext& ctx) override {
    auto& src = ctx.device_read<FakeDeviceBuffer>(in_);
    const auto& host_in = ctx.shape_of(in_);
    auto& dst = ctx.device_write<FakeDeviceBuffer>(out_, [&](DepthMap& d) { d.resize(host_in.width(), host_in.height()); });
    std::vector<float> values(src.bytes.size() / sizeof(float));
    std::memcpy(values.data(), src.bytes.data(), src.bytes.size());
    for (float& v : values) v += 10.f;
    std::memcpy(dst.bytes.data(), values.data(), dst.bytes.size());
    ctx.report_device_ms(0.5);
  }

 private:
  std::string input_, output_, name_;
  Read<DepthMap> in_;
  Write<DepthMap> out_;
};

class HostReader final : public Stage {
 public:
  std::string name() const override { return "host_reader"; }
  bool has_side_effects() const override { return true; }
  void declare(StageBuilder& b) override { in_ = b.read<DepthMap>("plus_ten"); }
  void run(StageContext& ctx) override { seen.push_back(ctx.get(in_)(1, 1)); }
  std::vector<float> seen;

 private:
  Read<DepthMap> in_;
};

TEST(FrameGraph, GraphTransfersBetweenHostAndDeviceOnlyWhenNeeded) {
  FakeDevice device;
  FrameGraph graph(&device);
  graph.emplace<CountingSource>(2);
  graph.emplace<DeviceAddTen>();
  auto& reader = graph.emplace<HostReader>();
  while (graph.run_frame()) {
  }
  EXPECT_EQ(reader.seen, (std::vector<float>{11.f, 12.f}));
  EXPECT_EQ(device.uploads, 2);    // the source's depth, once per frame
  EXPECT_EQ(device.downloads, 2);  // the device result, once per frame for the host reader
  const auto& timings = graph.timings();
  const auto device_stage = std::find_if(timings.begin(), timings.end(), [](auto& t) { return t.stage == "device_add_ten"; });
  ASSERT_NE(device_stage, timings.end());
  EXPECT_EQ(device_stage->device_ms, (std::vector<double>{0.5, 0.5}));
}

TEST(FrameGraph, ChainedDeviceStagesKeepDataOnTheDevice) {
  FakeDevice device;
  FrameGraph graph(&device);
  graph.emplace<CountingSource>(1);
  graph.emplace<DeviceAddTen>("depth", "plus_ten_first", "first");
  graph.emplace<DeviceAddTen>("plus_ten_first", "plus_ten", "second");
  auto& reader = graph.emplace<HostReader>();
  ASSERT_TRUE(graph.run_frame());
  EXPECT_EQ(reader.seen, std::vector<float>{21.f});
  EXPECT_EQ(device.uploads, 1);
  EXPECT_EQ(device.downloads, 1);
}

// "Vulkan" temporal stage: sum = depth + the previous frame's sum, all on the fake device.
class DeviceRunningSum final : public Stage {
 public:
  std::string name() const override { return "device_running_sum"; }
  Backend backend() const override { return Backend::Vulkan; }
  void declare(StageBuilder& b) override {
    in_ = b.read<DepthMap>("depth");
    previous_ = b.read_previous<DepthMap>("sum");
    out_ = b.write<DepthMap>("sum");
  }
  void run(StageContext& ctx) override {
    auto& src = ctx.device_read<FakeDeviceBuffer>(in_);
    const FakeDeviceBuffer* previous = ctx.device_read<FakeDeviceBuffer>(previous_);
    const DepthMap* previous_shape = ctx.shape_of(previous_);
    had_previous.push_back(previous != nullptr && previous_shape && previous_shape->width() == 4);
    const auto& shape = ctx.shape_of(in_);
    auto& dst = ctx.device_write<FakeDeviceBuffer>(out_, [&](DepthMap& d) { d.resize(shape.width(), shape.height()); });
    std::vector<float> values(src.bytes.size() / sizeof(float)), last(values.size(), 0.f);
    std::memcpy(values.data(), src.bytes.data(), src.bytes.size());
    if (previous) std::memcpy(last.data(), previous->bytes.data(), previous->bytes.size());
    for (std::size_t i = 0; i < values.size(); ++i) values[i] += last[i];
    std::memcpy(dst.bytes.data(), values.data(), dst.bytes.size());
  }
  std::vector<bool> had_previous;

 private:
  Read<DepthMap> in_;
  ReadPrevious<DepthMap> previous_;
  Write<DepthMap> out_;
};

TEST(FrameGraph, DeviceHistoryStaysOnTheDeviceAndItsBuffersAreReused) {
  FakeDevice device;
  FrameGraph graph(&device);
  graph.emplace<CountingSource>(10);
  auto& sum = graph.emplace<DeviceRunningSum>();
  graph.keep("sum");
  int allocations_after_two_frames = 0;
  for (int frame = 0; frame < 10; ++frame) {
    ASSERT_TRUE(graph.run_frame());
    if (frame == 1) allocations_after_two_frames = device.allocations;
  }
  EXPECT_EQ(sum.had_previous, (std::vector<bool>{false, true, true, true, true, true, true, true, true, true}));
  EXPECT_EQ(device.uploads, 10);   // the source's depth only: the history never leaves the device
  EXPECT_EQ(device.downloads, 0);  // nobody read a sum on the host yet
  // Two device buffers for the double-buffered sum and one for the depth, made in the first two
  // frames; the next eight frames reuse them.
  EXPECT_EQ(allocations_after_two_frames, 3);
  EXPECT_EQ(device.allocations, 3);
  const DepthMap* result = graph.find<DepthMap>("sum");
  ASSERT_NE(result, nullptr);
  EXPECT_FLOAT_EQ((*result)(1, 1), 55.f);  // 1 + 2 + ... + 10
  EXPECT_EQ(device.downloads, 1);
}

/// Host-only state that a "Vulkan" stage keeps across frames through the graph's history.
struct RunCount {
  int runs = 0;
};

// A "Vulkan" stage counting its runs in its own history, and optionally adding another stage's
// host-only value (as Vulkan stages read frame info and poses on the host).
class DeviceStageWithHostState final : public Stage {
 public:
  explicit DeviceStageWithHostState(bool read_foreign) : read_foreign_(read_foreign) {}
  std::string name() const override { return "device_with_state"; }
  Backend backend() const override { return Backend::Vulkan; }
  bool has_side_effects() const override { return true; }
  void declare(StageBuilder& b) override {
    previous_ = b.read_previous<RunCount>("run_count");
    count_ = b.write<RunCount>("run_count");
    if (read_foreign_) foreign_ = b.read<RunCount>("foreign_count");
  }
  void run(StageContext& ctx) override {
    const RunCount* previous = ctx.get(previous_);
    ctx.get(count_).runs = (previous ? previous->runs : 0) + 1 + (read_foreign_ ? ctx.get(foreign_).runs : 0);
    runs_seen.push_back(ctx.get(count_).runs);
  }
  std::vector<int> runs_seen;

 private:
  bool read_foreign_;
  ReadPrevious<RunCount> previous_;
  Write<RunCount> count_;
  Read<RunCount> foreign_;
};

class HostCountSource final : public Stage {
 public:
  std::string name() const override { return "host_count"; }
  void declare(StageBuilder& b) override { out_ = b.write<RunCount>("foreign_count"); }
  void run(StageContext& ctx) override { ctx.get(out_).runs = 7; }

 private:
  Write<RunCount> out_;
};

TEST(FrameGraph, AVulkanStageReadsHostOnlyBuffersAndItsOwnStateOnTheHost) {
  FakeDevice device;
  FrameGraph graph(&device);
  auto& stage = graph.emplace<DeviceStageWithHostState>(false);
  for (int frame = 0; frame < 3; ++frame) ASSERT_TRUE(graph.run_frame());
  EXPECT_EQ(stage.runs_seen, (std::vector<int>{1, 2, 3}));  // each frame continues the last one's
  EXPECT_EQ(device.uploads + device.downloads, 0);          // host state never travels

  FrameGraph foreign(&device);
  foreign.emplace<HostCountSource>();
  auto& reader = foreign.emplace<DeviceStageWithHostState>(true);
  for (int frame = 0; frame < 2; ++frame) ASSERT_TRUE(foreign.run_frame());
  EXPECT_EQ(reader.runs_seen, (std::vector<int>{8, 16}));  // + the other stage's 7 each frame
  EXPECT_EQ(device.uploads + device.downloads, 0);
}

TEST(FrameGraph, VulkanStageWithoutDeviceIsAGraphError) {
  FrameGraph graph;
  graph.emplace<CountingSource>(1);
  graph.emplace<DeviceAddTen>();
  graph.emplace<HostReader>();
  EXPECT_NE(compile_error(graph).find("no Vulkan device"), std::string::npos);
}

}  // namespace
}  // namespace relight
