#pragma once
// report.json's "device_memory" for replay and live: the Vulkan device memory allocations of the
// run, and those made after its second frame. A steady run makes none after frame 2 (every stage
// keeps its device buffers, the graph double-buffers history), so a count that grows with the
// run's length is a leak of Vulkan objects (scripts/soak.sh checks it over 10 000 frames).
#include <cstdint>
#include <nlohmann/json.hpp>

#include "relight/vk/context.h"

namespace relight::app {

class DeviceMemoryWatch {
 public:
  /// `context` may be null (nothing on Vulkan): add_to() then adds nothing.
  explicit DeviceMemoryWatch(const vk::VulkanContext* context) : context_(context) {}
  /// Called after each frame with the frames run so far.
  void after_frame(std::int64_t frames_run) {
    if (context_ != nullptr && frames_run == 2) at_frame_2_ = context_->memory_allocations();
  }
  /// Adds "device_memory" to `report` when a Vulkan device was used; `frames_run`: the run's frames.
  void add_to(nlohmann::ordered_json& report, std::int64_t frames_run) const {
    if (context_ == nullptr) return;
    const std::uint64_t allocations = context_->memory_allocations();
    report["device_memory"] = {{"allocations", allocations},
                               {"allocations_after_frame_2", frames_run > 2 ? allocations - at_frame_2_ : 0}};
  }

 private:
  const vk::VulkanContext* context_;
  std::uint64_t at_frame_2_ = 0;
};

}  // namespace relight::app
