#pragma once
// VulkanBuffer: a VkBuffer with its own VkDeviceMemory; the device side of a frame-graph buffer
// (it is a relight::DeviceBuffer) and the staging buffers that feed it.
//
// Memory: each buffer gets one allocation (no sub-allocator yet; fine for the few dozen buffers a
// frame graph holds). Where the chosen memory is host-visible (lavapipe, integrated GPUs,
// resizable BAR) the buffer stays mapped and the host reads/writes it directly; otherwise
// (discrete GPUs, or VulkanOptions::force_staging) VulkanTransfer copies through staging buffers.
#include <vulkan/vulkan.h>

#include <cstddef>
#include <optional>
#include <span>

#include "relight/core/device_transfer.h"
#include "relight/vk/handles.h"

namespace relight::vk {

class VulkanContext;

enum class BufferDomain {
  Device,    ///< GPU-local storage buffer (DEVICE_LOCAL preferred); mapped only if host-visible
  Upload,    ///< host -> device staging (HOST_VISIBLE, HOST_COHERENT preferred), always mapped
  Readback,  ///< device -> host staging (HOST_VISIBLE, HOST_CACHED preferred), always mapped
};

class VulkanBuffer final : public DeviceBuffer {
 public:
  /// A buffer of `bytes` bytes usable as storage buffer and copy source/destination, plus
  /// `extra_usage`. Zero bytes is allowed (Vulkan is given a tiny buffer; size_bytes() stays 0).
  VulkanBuffer(const VulkanContext& context, std::size_t bytes, BufferDomain domain = BufferDomain::Device,
               VkBufferUsageFlags extra_usage = 0);
  VulkanBuffer(VulkanBuffer&& other) noexcept;
  VulkanBuffer& operator=(VulkanBuffer&& other) noexcept;

  [[nodiscard]] std::size_t size_bytes() const override { return size_; }
  [[nodiscard]] VkBuffer handle() const { return buffer_.get(); }
  /// The size Vulkan knows (>= size_bytes(), never 0); use it for descriptor ranges.
  [[nodiscard]] VkDeviceSize vulkan_size() const { return vulkan_size_; }

  /// True when the host can read/write the buffer directly through write()/read().
  [[nodiscard]] bool host_mapped() const { return mapped_ != nullptr; }
  /// Copies `source` to the start of the mapped buffer (flushing non-coherent memory).
  /// Requires host_mapped() and source.size() <= size_bytes().
  void write(std::span<const std::byte> source);
  /// Copies the start of the mapped buffer into `destination` (invalidating non-coherent memory
  /// first). Requires host_mapped() and destination.size() <= size_bytes().
  void read(std::span<std::byte> destination) const;
  /// The mapped buffer itself, for the host to read in place where a copy would cost more than
  /// the reads (non-coherent memory is invalidated first); empty when not host_mapped(). Valid
  /// until the buffer is destroyed; the device must not be writing it meanwhile.
  [[nodiscard]] std::span<const std::byte> mapped_bytes() const;

 private:
  UniqueMemory memory_;  // declared first, so the buffer is destroyed before its memory is freed
  UniqueBuffer buffer_;
  std::size_t size_ = 0;
  VkDeviceSize vulkan_size_ = 0;
  std::byte* mapped_ = nullptr;  // unmapped implicitly when memory_ is freed
  bool coherent_ = true;
};

/// `slot`'s buffer of exactly `bytes` (device domain), made only when it is empty or its size
/// changed: a stage's per-frame scratch, so that same-sized frames allocate nothing.
VulkanBuffer& buffer_of_size(std::optional<VulkanBuffer>& slot, const VulkanContext& context, std::size_t bytes);

/// Makes `slot` hold at least `bytes`: kept while large enough, otherwise remade with a quarter
/// more, for data whose size changes every frame (ISM points, K-means points, the scene's
/// vertices), so that a steady run stops allocating. True when it was remade: descriptor sets
/// bound to the old buffer must be bound again.
bool reserve_with_headroom(std::optional<VulkanBuffer>& slot, const VulkanContext& context, std::size_t bytes,
                           BufferDomain domain = BufferDomain::Device, VkBufferUsageFlags extra_usage = 0);

}  // namespace relight::vk
