#include "relight/core/frame_graph.h"

#include <cxxabi.h>
#include <time.h>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <optional>
#include <sstream>

namespace relight {

const char* to_string(Backend backend) { return backend == Backend::Vulkan ? "Vulkan" : "CPU"; }

namespace {
/// CPU time of the whole process so far (every thread), in milliseconds.
double process_cpu_ms() {
  timespec now{};
  if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now) != 0) return 0.0;
  return static_cast<double>(now.tv_sec) * 1e3 + static_cast<double>(now.tv_nsec) * 1e-6;
}
}  // namespace

std::string demangle(const char* mangled) {
  int status = 0;
  std::unique_ptr<char, decltype(&std::free)> name(abi::__cxa_demangle(mangled, nullptr, nullptr, &status),
                                                   &std::free);
  return status == 0 && name ? std::string(name.get()) : std::string(mangled);
}

struct FrameGraph::Declaration {
  BufferId buffer;
  detail::Access access;
  detail::BufferType type;
};

struct FrameGraph::StageEntry {
  std::unique_ptr<Stage> stage;
  std::string name;
  std::vector<Declaration> declarations;
  bool culled = false;
};

// One buffer's current and previous versions, each with a host copy and an optional device copy.
// `host_fresh`/`device_fresh` say which copy holds this version's newest data.
struct FrameGraph::BufferState {
  struct Version {
    std::unique_ptr<detail::AnyBuffer> host;
    std::unique_ptr<DeviceBuffer> device;
    bool host_fresh = false;
    bool device_fresh = false;
    /// The device copy, uploaded first when only the host copy holds the newest data.
    DeviceBuffer& device_copy(DeviceTransfer& transfer);
    /// The host copy, downloaded first when only the device copy holds the newest data.
    detail::AnyBuffer& host_copy(DeviceTransfer* transfer);
  };
  std::string name;
  std::optional<std::size_t> writer;
  std::optional<detail::BufferType> type;  // the writer's type once validated
  bool has_history_reader = false;
  bool kept = false;
  bool written_this_frame = false;
  bool previous_valid = false;
  Version current;
  Version previous;
};

FrameGraph::FrameGraph(DeviceTransfer* device) : device_(device) {}
FrameGraph::~FrameGraph() = default;

void FrameGraph::add(std::unique_ptr<Stage> stage) {
  if (compiled_) throw GraphError("cannot add stage '" + stage->name() + "' after the graph was compiled");
  const std::string name = stage->name();
  for (const auto& existing : stages_) {
    if (existing.name == name) throw GraphError("two stages are named '" + name + "'");
  }
  stages_.push_back({std::move(stage), name, {}, false});
  StageBuilder builder(*this, stages_.size() - 1);
  stages_.back().stage->declare(builder);
}

void FrameGraph::keep(std::string_view buffer) {
  for (auto& state : buffers_) {
    if (state.name == buffer) {
      state.kept = true;
      return;
    }
  }
  throw GraphError("keep(): no stage declares buffer '" + std::string(buffer) + "'");
}

BufferId StageBuilder::declare(std::string_view buffer, detail::Access access, detail::BufferType type) {
  return graph_.declare(stage_, buffer, access, std::move(type));
}

BufferId FrameGraph::declare(std::size_t stage, std::string_view buffer, detail::Access access,
                             detail::BufferType type) {
  if (buffer.empty()) throw GraphError("stage '" + stages_[stage].name + "' declares a buffer with an empty name");
  auto found = std::find_if(buffers_.begin(), buffers_.end(), [&](const auto& b) { return b.name == buffer; });
  if (found == buffers_.end()) {
    buffers_.push_back({});
    buffers_.back().name = std::string(buffer);
    found = std::prev(buffers_.end());
  }
  const auto id = static_cast<BufferId>(found - buffers_.begin());
  stages_[stage].declarations.push_back({id, access, std::move(type)});
  return id;
}

void FrameGraph::validate_writers() {
  for (std::size_t s = 0; s < stages_.size(); ++s) {
    for (const auto& decl : stages_[s].declarations) {
      if (decl.access != detail::Access::Write) continue;
      auto& buffer = buffers_[decl.buffer];
      if (buffer.writer) {
        throw GraphError("buffer '" + buffer.name + "' is written by both stage '" + stages_[*buffer.writer].name +
                         "' and stage '" + stages_[s].name + "'");
      }
      buffer.writer = s;
      buffer.type = decl.type;
    }
  }
}

void FrameGraph::validate_readers() {
  for (const auto& entry : stages_) {
    for (const auto& decl : entry.declarations) {
      if (decl.access == detail::Access::Write) continue;
      auto& buffer = buffers_[decl.buffer];
      const char* how = decl.access == detail::Access::ReadPrevious ? "the previous frame of buffer '" : "buffer '";
      if (!buffer.writer) {
        throw GraphError("stage '" + entry.name + "' reads " + how + buffer.name + "' (" + decl.type.name +
                         ") but no stage writes it");
      }
      if (buffer.type->type != decl.type.type) {
        throw GraphError("stage '" + entry.name + "' reads " + how + buffer.name + "' as " + decl.type.name +
                         ", but stage '" + stages_[*buffer.writer].name + "' writes it as " + buffer.type->name);
      }
      if (decl.access == detail::Access::ReadPrevious) buffer.has_history_reader = true;
      // A Vulkan stage may read host-only buffers (frame info, poses, its own state across
      // frames) on the host; device_read accepts only mirrorable types, at compile time.
    }
    if (entry.stage->backend() == Backend::Vulkan && device_ == nullptr) {
      throw GraphError("stage '" + entry.name + "' runs on Vulkan but the graph has no Vulkan device");
    }
  }
}

// Kahn's algorithm; among ready stages the one added first runs first, so the order is stable.
void FrameGraph::order_stages() {
  const std::size_t n = stages_.size();
  std::vector<std::vector<std::size_t>> successors(n);
  std::vector<std::size_t> indegree(n, 0);
  for (std::size_t s = 0; s < n; ++s) {
    for (const auto& decl : stages_[s].declarations) {
      if (decl.access != detail::Access::Read) continue;
      const std::size_t writer = *buffers_[decl.buffer].writer;
      if (writer == s) throw GraphError("stage '" + stages_[s].name + "' reads its own output '" +
                                        buffers_[decl.buffer].name + "' (use read_previous for last frame's)");
      successors[writer].push_back(s);
      ++indegree[s];
    }
  }
  order_.clear();
  std::vector<bool> done(n, false);
  while (order_.size() < n) {
    std::optional<std::size_t> next;
    for (std::size_t s = 0; s < n && !next; ++s) {
      if (!done[s] && indegree[s] == 0) next = s;
    }
    if (!next) {
      std::string members;
      for (std::size_t s = 0; s < n; ++s) {
        if (!done[s]) members += (members.empty() ? "'" : ", '") + stages_[s].name + "'";
      }
      throw GraphError("the frame graph has a cycle among stages " + members);
    }
    done[*next] = true;
    order_.push_back(*next);
    for (std::size_t succ : successors[*next]) --indegree[succ];
  }
}

// A stage without side effects whose outputs nobody (stage or caller) uses is culled, to a fixpoint.
void FrameGraph::cull_stages() {
  bool changed = true;
  while (changed) {
    changed = false;
    std::vector<bool> buffer_used(buffers_.size(), false);
    for (std::size_t b = 0; b < buffers_.size(); ++b) buffer_used[b] = buffers_[b].kept;
    for (const auto& entry : stages_) {
      if (entry.culled) continue;
      for (const auto& decl : entry.declarations) {
        // Reading one's own previous output (temporal filters) does not make the output used.
        const bool own_history = buffers_[decl.buffer].writer == &entry - stages_.data();
        if (decl.access != detail::Access::Write && !own_history) buffer_used[decl.buffer] = true;
      }
    }
    for (auto& entry : stages_) {
      if (entry.culled || entry.stage->has_side_effects()) continue;
      const bool any_output_used = std::any_of(entry.declarations.begin(), entry.declarations.end(), [&](auto& d) {
        return d.access == detail::Access::Write && buffer_used[d.buffer];
      });
      if (!any_output_used) {
        entry.culled = true;
        changed = true;
      }
    }
  }
}

void FrameGraph::allocate_buffers() {
  for (auto& buffer : buffers_) {
    buffer.current.host = buffer.type->make();
    buffer.previous.host = buffer.type->make();
  }
  timings_.clear();
  for (std::size_t s : order_) {
    if (!stages_[s].culled) timings_.push_back({stages_[s].name, stages_[s].stage->backend(), {}, {}, {}});
  }
}

void FrameGraph::compile() {
  if (compiled_) return;
  validate_writers();
  validate_readers();
  order_stages();
  cull_stages();
  allocate_buffers();
  compiled_ = true;
}

bool FrameGraph::run_frame() {
  if (!compiled_) compile();
  begin_frame();
  std::size_t timing_index = 0;
  for (std::size_t s : order_) {
    auto& entry = stages_[s];
    if (entry.culled) continue;
    StageContext context(*this, s);
    const double cpu_start = process_cpu_ms();
    const auto start = std::chrono::steady_clock::now();
    entry.stage->run(context);
    const auto stop = std::chrono::steady_clock::now();
    const double cpu_stop = process_cpu_ms();
    if (context.end_of_stream_) return false;
    auto& timing = timings_[timing_index++];
    timing.wall_ms.push_back(std::chrono::duration<double, std::milli>(stop - start).count());
    timing.cpu_ms.push_back(cpu_stop - cpu_start);
    if (context.device_ms_ >= 0.0) timing.device_ms.push_back(context.device_ms_);
    timing.device_buffers = context.device_access_;
  }
  ++frames_run_;
  return true;
}

void FrameGraph::finish() {
  for (std::size_t s : order_) {
    if (!stages_[s].culled) stages_[s].stage->finish();
  }
}

// Last frame's results become "previous" only now, so that between frames find() still sees them.
void FrameGraph::begin_frame() {
  for (auto& buffer : buffers_) {
    if (buffer.has_history_reader && buffer.written_this_frame) {
      std::swap(buffer.current, buffer.previous);
      buffer.previous_valid = true;
    }
    buffer.written_this_frame = false;
  }
}

std::vector<std::string> FrameGraph::execution_order() const {
  std::vector<std::string> names;
  for (std::size_t s : order_) {
    if (!stages_[s].culled) names.push_back(stages_[s].name);
  }
  return names;
}

std::vector<std::string> FrameGraph::culled_stages() const {
  std::vector<std::string> names;
  for (const auto& entry : stages_) {
    if (entry.culled) names.push_back(entry.name);
  }
  return names;
}

namespace {
std::string dot_quote(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '\n') {
      quoted += "\\n";  // DOT's line break inside a label
      continue;
    }
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  return quoted + "\"";
}
}  // namespace

std::string FrameGraph::to_dot() const {
  std::ostringstream dot;
  dot << "digraph relight {\n  rankdir=LR;\n  node [fontname=\"Helvetica\", fontsize=10];\n";
  for (const auto& entry : stages_) {
    const bool vk = entry.stage->backend() == Backend::Vulkan;
    dot << "  " << dot_quote("stage:" + entry.name) << " [shape=box, style=\"rounded,filled\", fillcolor="
        << (entry.culled ? "\"#dddddd\"" : vk ? "\"#f4c7a1\"" : "\"#a9cce3\"")
        << ", label=" << dot_quote(entry.name + "\n" + to_string(entry.stage->backend()) +
                                   (entry.culled ? " (culled)" : ""))
        << "];\n";
  }
  for (const auto& buffer : buffers_) {
    const std::string type = buffer.type ? buffer.type->name : std::string("?");
    dot << "  " << dot_quote("buffer:" + buffer.name) << " [shape=ellipse, label="
        << dot_quote(buffer.name + "\n" + type) << "];\n";
  }
  for (const auto& entry : stages_) {
    for (const auto& decl : entry.declarations) {
      const std::string stage = dot_quote("stage:" + entry.name);
      const std::string buffer = dot_quote("buffer:" + buffers_[decl.buffer].name);
      switch (decl.access) {
        case detail::Access::Write: dot << "  " << stage << " -> " << buffer << ";\n"; break;
        case detail::Access::Read: dot << "  " << buffer << " -> " << stage << ";\n"; break;
        case detail::Access::ReadPrevious:
          dot << "  " << buffer << " -> " << stage << " [style=dashed, label=\"previous frame\"];\n";
          break;
      }
    }
  }
  dot << "}\n";
  return dot.str();
}

void FrameGraph::make_host_current(BufferState& buffer) { buffer.current.host_copy(device_); }

detail::AnyBuffer& FrameGraph::BufferState::Version::host_copy(DeviceTransfer* transfer) {
  if (!host_fresh && device_fresh) {
    transfer->download(*device, host->mutable_bytes());
    host_fresh = true;
  }
  return *host;
}

detail::AnyBuffer* FrameGraph::find_host(std::string_view name, std::type_index type) {
  for (auto& buffer : buffers_) {
    if (buffer.name != name) continue;
    if (!compiled_ || !buffer.type || buffer.type->type != type || !buffer.written_this_frame) return nullptr;
    make_host_current(buffer);
    return buffer.current.host.get();
  }
  return nullptr;
}

std::int64_t StageContext::frame_index() const { return graph_.frames_run_; }

void StageContext::check_declared(BufferId id, detail::Access access) const {
  for (const auto& decl : graph_.stages_[stage_].declarations) {
    if (decl.buffer == id && decl.access == access) return;
  }
  throw LogicError("stage '" + graph_.stages_[stage_].name + "' used buffer '" + graph_.buffers_.at(id).name +
                   "' through a handle it did not declare");
}

detail::AnyBuffer& StageContext::host_for_read(BufferId id) {
  check_declared(id, detail::Access::Read);
  auto& buffer = graph_.buffers_[id];
  graph_.make_host_current(buffer);
  return *buffer.current.host;
}

detail::AnyBuffer* StageContext::host_previous(BufferId id) {
  check_declared(id, detail::Access::ReadPrevious);
  auto& buffer = graph_.buffers_[id];
  return buffer.previous_valid ? &buffer.previous.host_copy(graph_.device_) : nullptr;
}

detail::AnyBuffer& StageContext::host_for_write(BufferId id) {
  check_declared(id, detail::Access::Write);
  auto& buffer = graph_.buffers_[id];
  buffer.written_this_frame = true;
  buffer.current.host_fresh = true;
  buffer.current.device_fresh = false;
  return *buffer.current.host;
}

detail::AnyBuffer& StageContext::host_without_sync(BufferId id) { return *graph_.buffers_[id].current.host; }

detail::AnyBuffer& StageContext::host_for_shape(BufferId id) {
  check_declared(id, detail::Access::Write);
  return *graph_.buffers_[id].current.host;
}

namespace {
void ensure_device_size(DeviceTransfer& device, std::unique_ptr<DeviceBuffer>& buffer, std::size_t bytes) {
  if (!buffer || buffer->size_bytes() != bytes) buffer = device.allocate(bytes);
}
}  // namespace

DeviceBuffer& FrameGraph::BufferState::Version::device_copy(DeviceTransfer& transfer) {
  if (!device_fresh) {
    const auto bytes = host->mutable_bytes();
    ensure_device_size(transfer, device, bytes.size());
    transfer.upload(bytes, *device);
    device_fresh = true;
  }
  return *device;
}

DeviceBuffer& StageContext::device_for_read(BufferId id) {
  check_declared(id, detail::Access::Read);
  device_access_ = true;
  return graph_.buffers_[id].current.device_copy(*graph_.device_);
}

detail::AnyBuffer* StageContext::host_previous_without_sync(BufferId id) {
  check_declared(id, detail::Access::ReadPrevious);
  auto& buffer = graph_.buffers_[id];
  return buffer.previous_valid ? buffer.previous.host.get() : nullptr;
}

DeviceBuffer* StageContext::device_for_previous(BufferId id) {
  check_declared(id, detail::Access::ReadPrevious);
  device_access_ = true;
  auto& buffer = graph_.buffers_[id];
  return buffer.previous_valid ? &buffer.previous.device_copy(*graph_.device_) : nullptr;
}

DeviceBuffer& StageContext::device_for_write(BufferId id) {
  device_access_ = true;
  auto& buffer = graph_.buffers_[id];
  auto& version = buffer.current;
  ensure_device_size(*graph_.device_, version.device, version.host->mutable_bytes().size());
  buffer.written_this_frame = true;
  version.device_fresh = true;
  version.host_fresh = false;
  return *version.device;
}

}  // namespace relight
