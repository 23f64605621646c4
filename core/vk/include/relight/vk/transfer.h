#pragma once
// VulkanTransfer: relight::DeviceTransfer for a VulkanContext, i.e. how the frame graph moves an
// image's bytes between host and device. allocate() returns VulkanBuffer (BufferDomain::Device),
// which is the type Vulkan stages ask for with ctx.device_read<VulkanBuffer>/device_write.
//
// Host-mapped buffers are copied with memcpy; others go through one reusable upload and one
// reusable readback staging buffer (grown on demand) and a copy command, waiting for the GPU.
#include <memory>
#include <optional>

#include "relight/core/device_transfer.h"
#include "relight/vk/buffer.h"

namespace relight::vk {

class VulkanContext;

class VulkanTransfer final : public DeviceTransfer {
 public:
  explicit VulkanTransfer(VulkanContext& context) : context_(context) {}

  [[nodiscard]] std::unique_ptr<DeviceBuffer> allocate(std::size_t bytes) override;
  /// `destination` must be a VulkanBuffer of at least source.size() bytes.
  void upload(std::span<const std::byte> source, DeviceBuffer& destination) override;
  /// `source` must be a VulkanBuffer of at least destination.size() bytes.
  void download(const DeviceBuffer& source, std::span<std::byte> destination) override;

 private:
  VulkanBuffer& staging(std::optional<VulkanBuffer>& slot, std::size_t bytes, BufferDomain domain);

  VulkanContext& context_;
  std::optional<VulkanBuffer> upload_staging_;
  std::optional<VulkanBuffer> readback_staging_;
};

}  // namespace relight::vk
