#include "relight/vk/buffer.h"

#include <algorithm>
#include <cstring>
#include <utility>

#include "relight/vk/check.h"
#include "relight/vk/context.h"

namespace relight::vk {

namespace {

struct MemoryWish {
  VkMemoryPropertyFlags required;
  VkMemoryPropertyFlags preferred;
};

MemoryWish memory_wish(BufferDomain domain) {
  switch (domain) {
    case BufferDomain::Device: return {0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT};
    case BufferDomain::Upload:
      return {VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT, VK_MEMORY_PROPERTY_HOST_COHERENT_BIT};
    case BufferDomain::Readback:
      return {VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT, VK_MEMORY_PROPERTY_HOST_CACHED_BIT};
  }
  return {0, 0};
}

}  // namespace

VulkanBuffer::VulkanBuffer(const VulkanContext& context, std::size_t bytes, BufferDomain domain,
                           VkBufferUsageFlags extra_usage)
    : size_(bytes), vulkan_size_(std::max<VkDeviceSize>(bytes, 4)) {
  const VkDevice device = context.device();
  VkBufferCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  info.size = vulkan_size_;
  info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
               VK_BUFFER_USAGE_TRANSFER_DST_BIT | extra_usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkBuffer buffer = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreateBuffer(device, &info, nullptr, &buffer));
  buffer_ = UniqueBuffer(device, buffer);

  VkMemoryRequirements requirements{};
  vkGetBufferMemoryRequirements(device, buffer, &requirements);
  const MemoryWish wish = memory_wish(domain);
  const std::uint32_t type = context.find_memory_type(requirements.memoryTypeBits, wish.required, wish.preferred);
  VkMemoryAllocateInfo allocate{};
  allocate.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  allocate.allocationSize = requirements.size;
  allocate.memoryTypeIndex = type;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkAllocateMemory(device, &allocate, nullptr, &memory));
  context.count_memory_allocation();
  memory_ = UniqueMemory(device, memory);
  RELIGHT_VK_CHECK(vkBindBufferMemory(device, buffer, memory, 0));

  const VkMemoryPropertyFlags flags = context.memory_properties().memoryTypes[type].propertyFlags;
  coherent_ = (flags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT) != 0;
  const bool may_map = domain != BufferDomain::Device || !context.force_staging();
  if ((flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) && may_map) {
    void* mapped = nullptr;
    RELIGHT_VK_CHECK(vkMapMemory(device, memory, 0, VK_WHOLE_SIZE, 0, &mapped));
    mapped_ = static_cast<std::byte*>(mapped);
  }
}

VulkanBuffer::VulkanBuffer(VulkanBuffer&& other) noexcept
    : memory_(std::move(other.memory_)),
      buffer_(std::move(other.buffer_)),
      size_(std::exchange(other.size_, 0)),
      vulkan_size_(std::exchange(other.vulkan_size_, 0)),
      mapped_(std::exchange(other.mapped_, nullptr)),
      coherent_(other.coherent_) {}

VulkanBuffer& VulkanBuffer::operator=(VulkanBuffer&& other) noexcept {
  if (this != &other) {
    buffer_ = std::move(other.buffer_);
    memory_ = std::move(other.memory_);
    size_ = std::exchange(other.size_, 0);
    vulkan_size_ = std::exchange(other.vulkan_size_, 0);
    mapped_ = std::exchange(other.mapped_, nullptr);
    coherent_ = other.coherent_;
  }
  return *this;
}

void VulkanBuffer::write(std::span<const std::byte> source) {
  if (!mapped_ || source.size() > size_) throw LogicError("VulkanBuffer::write: buffer not mapped or too small");
  if (source.empty()) return;
  std::memcpy(mapped_, source.data(), source.size());
  if (!coherent_) {
    VkMappedMemoryRange range{};
    range.sType = VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE;
    range.memory = memory_.get();
    range.size = VK_WHOLE_SIZE;
    RELIGHT_VK_CHECK(vkFlushMappedMemoryRanges(memory_.device(), 1, &range));
  }
}

void VulkanBuffer::read(std::span<std::byte> destination) const {
  if (!mapped_ || destination.size() > size_) throw LogicError("VulkanBuffer::read: buffer not mapped or too small");
  if (destination.empty()) return;
  const std::span<const std::byte> mapped = mapped_bytes();
  std::memcpy(destination.data(), mapped.data(), destination.size());
}

std::span<const std::byte> VulkanBuffer::mapped_bytes() const {
  if (!mapped_) return {};
  if (!coherent_) {
    VkMappedMemoryRange range{};
    range.sType = VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE;
    range.memory = memory_.get();
    range.size = VK_WHOLE_SIZE;
    RELIGHT_VK_CHECK(vkInvalidateMappedMemoryRanges(memory_.device(), 1, &range));
  }
  return {mapped_, size_};
}

VulkanBuffer& buffer_of_size(std::optional<VulkanBuffer>& slot, const VulkanContext& context, std::size_t bytes) {
  if (!slot || slot->size_bytes() != bytes) slot.emplace(context, bytes);
  return *slot;
}

bool reserve_with_headroom(std::optional<VulkanBuffer>& slot, const VulkanContext& context, std::size_t bytes,
                           BufferDomain domain, VkBufferUsageFlags extra_usage) {
  if (slot && slot->size_bytes() >= bytes) return false;
  slot.reset();  // free the old memory before the new allocation
  slot.emplace(context, bytes + bytes / 4, domain, extra_usage);
  return true;
}

}  // namespace relight::vk
