#include "relight/vk/transfer.h"

#include "relight/core/error.h"
#include "relight/vk/context.h"

namespace relight::vk {

namespace {

template <class Buffer, class Base>
Buffer& as_vulkan(Base& buffer) {
  auto* vulkan = dynamic_cast<Buffer*>(&buffer);
  if (!vulkan) throw LogicError("VulkanTransfer was given a device buffer that is not a VulkanBuffer");
  return *vulkan;
}

void copy(VulkanContext& context, VkBuffer from, VkBuffer to, std::size_t bytes) {
  context.submit([&](VkCommandBuffer cmd) {
    const VkBufferCopy region{0, 0, bytes};
    vkCmdCopyBuffer(cmd, from, to, 1, &region);
  });
}

}  // namespace

std::unique_ptr<DeviceBuffer> VulkanTransfer::allocate(std::size_t bytes) {
  return std::make_unique<VulkanBuffer>(context_, bytes, BufferDomain::Device);
}

VulkanBuffer& VulkanTransfer::staging(std::optional<VulkanBuffer>& slot, std::size_t bytes, BufferDomain domain) {
  if (!slot || slot->size_bytes() < bytes) slot.emplace(context_, bytes, domain);
  return *slot;
}

void VulkanTransfer::upload(std::span<const std::byte> source, DeviceBuffer& destination) {
  auto& device = as_vulkan<VulkanBuffer>(destination);
  if (source.size() > device.size_bytes()) throw LogicError("VulkanTransfer::upload: source larger than the device buffer");
  if (source.empty()) return;
  if (device.host_mapped()) return device.write(source);
  VulkanBuffer& stage = staging(upload_staging_, source.size(), BufferDomain::Upload);
  stage.write(source);
  copy(context_, stage.handle(), device.handle(), source.size());
}

void VulkanTransfer::download(const DeviceBuffer& source, std::span<std::byte> destination) {
  const auto& device = as_vulkan<const VulkanBuffer>(source);
  if (destination.size() > device.size_bytes()) {
    throw LogicError("VulkanTransfer::download: destination larger than the device buffer");
  }
  if (destination.empty()) return;
  if (device.host_mapped()) return device.read(destination);
  VulkanBuffer& stage = staging(readback_staging_, destination.size(), BufferDomain::Readback);
  copy(context_, device.handle(), stage.handle(), destination.size());
  stage.read(destination);
}

}  // namespace relight::vk
