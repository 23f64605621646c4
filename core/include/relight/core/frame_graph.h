#pragma once
// The frame graph: the spine that connects relight's stages.
//
// A Stage declares, once, which named buffers it reads and writes and with which C++ type
// (StageBuilder::read/write/read_previous return typed handles). FrameGraph::compile() checks the
// declarations (every read has exactly one writer of the same type, no cycles, unique stage names),
// orders the stages topologically and culls stages whose results nobody uses. run_frame() then
// runs the stages in that order, owns every buffer, hands each stage its inputs through the typed
// handles (no casts, no string lookups at run time), keeps the previous frame's version of every
// buffer that some stage reads with read_previous(), and times each stage.
//
// Vulkan stages get device copies of buffers through StageContext::device_read/device_write; the
// graph moves the bytes between host and device when the other side holds newer data, so stages
// never transfer a graph buffer themselves. (A stage that dispatches from host buffers - DIR,
// K-means - uploads only what it derives from them: meshes, gathered points. StageTimings'
// device_buffers tells the two kinds apart.)
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <typeindex>
#include <vector>

#include "relight/core/buffer_name.h"
#include "relight/core/device_transfer.h"
#include "relight/core/error.h"

namespace relight {

/// Thrown by FrameGraph::compile for a malformed graph; the message names stage and buffer.
class GraphError : public LogicError {
 public:
  using LogicError::LogicError;
};

enum class Backend { Cpu, Vulkan };
[[nodiscard]] const char* to_string(Backend backend);

using BufferId = std::uint32_t;

/// Typed handles to a buffer, returned by StageBuilder. The type travels with the handle, so
/// StageContext::get returns the right C++ type without a cast and misuse fails to compile.
template <class T>
struct Read { BufferId id = 0; };
template <class T>
struct ReadPrevious { BufferId id = 0; };
template <class T>
struct Write { BufferId id = 0; };

/// What a buffer type must offer: the graph default-constructs, moves and swaps them.
template <class T>
concept GraphBuffer = std::default_initializable<T> && std::movable<T>;
/// Buffers whose bytes can be mirrored on a device (images of trivially copyable pixels).
template <class T>
concept DeviceMirrorable = GraphBuffer<T> && requires(T t, const T ct) {
  { t.bytes() } -> std::convertible_to<std::span<std::byte>>;
  { ct.bytes() } -> std::convertible_to<std::span<const std::byte>>;
};

std::string demangle(const char* mangled);

/// Human-readable type name for error messages and DOT output.
template <class T>
std::string buffer_type_name() {
  if constexpr (requires { T::type_name; }) {
    return T::type_name;
  } else {
    return demangle(typeid(T).name());
  }
}

namespace detail {
class AnyBuffer {
 public:
  virtual ~AnyBuffer() = default;
  [[nodiscard]] virtual std::span<std::byte> mutable_bytes() = 0;  // empty when not mirrorable
};
template <class T>
class TypedBuffer final : public AnyBuffer {
 public:
  T value{};
  std::span<std::byte> mutable_bytes() override {
    if constexpr (DeviceMirrorable<T>) {
      return value.bytes();
    } else {
      return {};
    }
  }
};
struct BufferType {
  std::type_index type;
  std::string name;
  std::function<std::unique_ptr<AnyBuffer>()> make;
  bool device_mirrorable = false;
};
template <class T>
BufferType buffer_type() {
  return {typeid(T), buffer_type_name<T>(), [] { return std::make_unique<TypedBuffer<T>>(); },
          DeviceMirrorable<T>};
}
enum class Access { Read, ReadPrevious, Write };
}  // namespace detail

class FrameGraph;

/// Passed to Stage::declare: records what the stage reads and writes.
class StageBuilder {
 public:
  template <GraphBuffer T>
  [[nodiscard]] Read<T> read(std::string_view buffer) {
    return {declare(buffer, detail::Access::Read, detail::buffer_type<T>())};
  }
  /// The previous frame's version of a buffer; StageContext::get returns nullptr on the first
  /// frame. Does not order this stage after the writer (so a stage may read its own output).
  template <GraphBuffer T>
  [[nodiscard]] ReadPrevious<T> read_previous(std::string_view buffer) {
    return {declare(buffer, detail::Access::ReadPrevious, detail::buffer_type<T>())};
  }
  template <GraphBuffer T>
  [[nodiscard]] Write<T> write(std::string_view buffer) {
    return {declare(buffer, detail::Access::Write, detail::buffer_type<T>())};
  }
  /// The same with a typed name (buffer_name.h): the handle's type is the name's.
  template <GraphBuffer T>
  [[nodiscard]] Read<T> read(BufferName<T> buffer) {
    return read<T>(buffer.name());
  }
  template <GraphBuffer T>
  [[nodiscard]] ReadPrevious<T> read_previous(BufferName<T> buffer) {
    return read_previous<T>(buffer.name());
  }
  template <GraphBuffer T>
  [[nodiscard]] Write<T> write(BufferName<T> buffer) {
    return write<T>(buffer.name());
  }

 private:
  friend class FrameGraph;
  StageBuilder(FrameGraph& graph, std::size_t stage) : graph_(graph), stage_(stage) {}
  BufferId declare(std::string_view buffer, detail::Access access, detail::BufferType type);
  FrameGraph& graph_;
  std::size_t stage_;
};

/// Passed to Stage::run: typed access to this frame's buffers.
class StageContext {
 public:
  template <class T>
  [[nodiscard]] const T& get(Read<T> handle) {
    return typed<T>(host_for_read(handle.id));
  }
  /// nullptr when there is no previous frame (first frame, or the writer did not run).
  template <class T>
  [[nodiscard]] const T* get(ReadPrevious<T> handle) {
    detail::AnyBuffer* previous = host_previous(handle.id);
    return previous ? &typed<T>(*previous) : nullptr;
  }
  /// The stage must fully overwrite the buffer: it holds stale data from an earlier frame.
  template <class T>
  [[nodiscard]] T& get(Write<T> handle) {
    return typed<T>(host_for_write(handle.id));
  }

  /// The host object of an input for its shape (width, height) only: its pixels may be stale
  /// when a Vulkan stage wrote the buffer, and reading it this way never downloads them.
  template <class T>
  [[nodiscard]] const T& shape_of(Read<T> handle) {
    check_declared(handle.id, detail::Access::Read);
    return typed<T>(host_without_sync(handle.id));
  }

  /// Device copy of an input, uploaded by the graph if the host copy is newer.
  template <class D, DeviceMirrorable T>
  [[nodiscard]] D& device_read(Read<T> handle) {
    return device_cast<D>(device_for_read(handle.id));
  }
  /// Device copy of the previous frame's version of a buffer (device-resident history: the graph
  /// keeps both frames' device buffers and swaps them, uploading only when the previous version
  /// exists on the host alone); nullptr when there is no previous frame.
  template <class D, DeviceMirrorable T>
  [[nodiscard]] D* device_read(ReadPrevious<T> handle) {
    DeviceBuffer* previous = device_for_previous(handle.id);
    return previous ? &device_cast<D>(*previous) : nullptr;
  }
  /// The previous frame's host object for its shape only (never downloads); nullptr as get().
  template <class T>
  [[nodiscard]] const T* shape_of(ReadPrevious<T> handle) {
    detail::AnyBuffer* previous = host_previous_without_sync(handle.id);
    return previous ? &typed<T>(*previous) : nullptr;
  }
  /// Device buffer for an output. `shape` sets the host buffer's shape (its contents are filled
  /// by a download only when a CPU stage or the caller later reads it).
  template <class D, DeviceMirrorable T, std::invocable<T&> Shape>
  [[nodiscard]] D& device_write(Write<T> handle, Shape&& shape) {
    shape(typed<T>(host_for_shape(handle.id)));
    return device_cast<D>(device_for_write(handle.id));
  }

  [[nodiscard]] std::int64_t frame_index() const;
  /// A source stage calls this when it has no more frames: the graph stops this frame here.
  void end_of_stream() { end_of_stream_ = true; }
  /// A Vulkan stage reports its GPU time (timestamp queries) for the timing table.
  void report_device_ms(double milliseconds) { device_ms_ = milliseconds; }

 private:
  friend class FrameGraph;
  StageContext(FrameGraph& graph, std::size_t stage) : graph_(graph), stage_(stage) {}
  template <class T>
  static T& typed(detail::AnyBuffer& buffer) {
    return static_cast<detail::TypedBuffer<T>&>(buffer).value;  // type checked at compile()
  }
  template <class D>
  static D& device_cast(DeviceBuffer& buffer) {
    auto* typed_device = dynamic_cast<D*>(&buffer);
    if (!typed_device) throw LogicError("device buffer is not of the requested device type");
    return *typed_device;
  }
  detail::AnyBuffer& host_for_read(BufferId id);
  detail::AnyBuffer* host_previous(BufferId id);
  detail::AnyBuffer& host_for_write(BufferId id);
  detail::AnyBuffer& host_for_shape(BufferId id);
  detail::AnyBuffer& host_without_sync(BufferId id);
  detail::AnyBuffer* host_previous_without_sync(BufferId id);
  DeviceBuffer& device_for_read(BufferId id);
  DeviceBuffer* device_for_previous(BufferId id);
  DeviceBuffer& device_for_write(BufferId id);
  void check_declared(BufferId id, detail::Access access) const;

  FrameGraph& graph_;
  std::size_t stage_;
  bool end_of_stream_ = false;
  bool device_access_ = false;  ///< device_read or device_write was called this run
  double device_ms_ = -1.0;
};

/// One unit of work in the graph. declare() is called once by FrameGraph::add; run() once per frame.
class Stage {
 public:
  virtual ~Stage() = default;
  [[nodiscard]] virtual std::string name() const = 0;
  /// Where the stage's work runs: Vulkan when it dispatches to the GPU, whether its graph
  /// buffers live on the device (device_read/device_write) or on the host (StageTimings says
  /// which it used). Chosen by the stage's factory (core/stage_backend.h).
  [[nodiscard]] virtual Backend backend() const { return Backend::Cpu; }
  /// Stages with effects outside the graph (sources, writers) are never culled.
  [[nodiscard]] virtual bool has_side_effects() const { return false; }
  virtual void declare(StageBuilder& builder) = 0;
  virtual void run(StageContext& context) = 0;
  /// Called once by FrameGraph::finish() after the last frame (end of stream, --frames limit or
  /// Ctrl-C), so that writers can finalise files that cover the whole run.
  virtual void finish() {}
};

/// Per-stage timing over all frames run so far (milliseconds).
struct StageTimings {
  std::string stage;
  Backend backend = Backend::Cpu;
  std::vector<double> wall_ms;    ///< one entry per frame the stage ran in
  std::vector<double> device_ms;  ///< GPU time where the stage reported it (else empty)
  /// The process's CPU time while the stage ran, all threads together (its helper threads, the
  /// Vulkan CPU device's, and any background writer's): cpu_ms / wall_ms says how many cores the
  /// stage kept busy.
  std::vector<double> cpu_ms;
  /// Whether the stage's last run read or wrote graph buffers on the device (else on the host).
  bool device_buffers = false;
};

class FrameGraph {
 public:
  /// `device` may be null: Vulkan stages then cannot run (compile() says so).
  explicit FrameGraph(DeviceTransfer* device = nullptr);
  ~FrameGraph();
  FrameGraph(const FrameGraph&) = delete;
  FrameGraph& operator=(const FrameGraph&) = delete;

  /// Adds a stage and records its declarations. Returns the stage for the caller's convenience.
  template <class S, class... Args>
  S& emplace(Args&&... args) {
    auto stage = std::make_unique<S>(std::forward<Args>(args)...);
    S& ref = *stage;
    add(std::move(stage));
    return ref;
  }
  void add(std::unique_ptr<Stage> stage);
  /// Marks a buffer as a result of the graph (read by the caller through find()), so that its
  /// writer is not culled even though no stage reads it.
  void keep(std::string_view buffer);
  template <class T>
  void keep(BufferName<T> buffer) {
    keep(buffer.name());
  }

  /// Validates and orders the graph; throws GraphError naming the offending stage and buffer.
  void compile();
  /// Runs one frame. Returns false when a source signalled end of stream (nothing after it ran).
  bool run_frame();
  /// Lets every (non-culled) stage finalise its outputs, in execution order. Call once, after the
  /// last run_frame().
  void finish();

  [[nodiscard]] std::int64_t frames_run() const { return frames_run_; }
  /// Stage names in execution order (after compile), culled stages excluded.
  [[nodiscard]] std::vector<std::string> execution_order() const;
  [[nodiscard]] std::vector<std::string> culled_stages() const;
  [[nodiscard]] const std::vector<StageTimings>& timings() const { return timings_; }
  /// Graphviz DOT: stages as boxes, buffers as ellipses, history reads dashed.
  [[nodiscard]] std::string to_dot() const;

  /// Host copy of a buffer after a frame (downloads from the device if needed); nullptr when
  /// the buffer does not exist, has another type, or was not written this frame.
  template <class T>
  [[nodiscard]] const T* find(std::string_view buffer) {
    detail::AnyBuffer* any = find_host(buffer, typeid(T));
    return any ? &static_cast<detail::TypedBuffer<T>*>(any)->value : nullptr;
  }
  template <class T>
  [[nodiscard]] const T* find(BufferName<T> buffer) {
    return find<T>(buffer.name());
  }

 private:
  friend class StageBuilder;
  friend class StageContext;
  struct Declaration;
  struct BufferState;
  struct StageEntry;

  BufferId declare(std::size_t stage, std::string_view buffer, detail::Access access, detail::BufferType type);
  detail::AnyBuffer* find_host(std::string_view buffer, std::type_index type);
  void validate_writers();
  void validate_readers();
  void order_stages();
  void cull_stages();
  void allocate_buffers();
  void begin_frame();
  void make_host_current(BufferState& buffer);

  DeviceTransfer* device_;
  std::vector<StageEntry> stages_;
  std::vector<BufferState> buffers_;
  std::vector<std::size_t> order_;
  std::vector<StageTimings> timings_;
  bool compiled_ = false;
  std::int64_t frames_run_ = 0;
};

}  // namespace relight
