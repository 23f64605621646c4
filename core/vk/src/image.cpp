#include "relight/vk/image.h"

#include "relight/vk/check.h"
#include "relight/vk/context.h"

namespace relight::vk {

VulkanImage::VulkanImage(const VulkanContext& context, std::uint32_t width, std::uint32_t height, VkFormat format,
                         VkImageUsageFlags usage, VkImageAspectFlags aspect)
    : format_(format), width_(width), height_(height) {
  const VkDevice device = context.device();
  VkImageCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = format;
  info.extent = {width, height, 1};
  info.mipLevels = 1;
  info.arrayLayers = 1;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = usage;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkImage image = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreateImage(device, &info, nullptr, &image));
  image_ = UniqueImage(device, image);

  VkMemoryRequirements requirements{};
  vkGetImageMemoryRequirements(device, image, &requirements);
  VkMemoryAllocateInfo allocate{};
  allocate.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  allocate.allocationSize = requirements.size;
  allocate.memoryTypeIndex = context.find_memory_type(requirements.memoryTypeBits, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkAllocateMemory(device, &allocate, nullptr, &memory));
  context.count_memory_allocation();
  memory_ = UniqueMemory(device, memory);
  RELIGHT_VK_CHECK(vkBindImageMemory(device, image, memory, 0));

  VkImageViewCreateInfo view_info{};
  view_info.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
  view_info.image = image;
  view_info.viewType = VK_IMAGE_VIEW_TYPE_2D;
  view_info.format = format;
  view_info.subresourceRange = {aspect, 0, 1, 0, 1};
  VkImageView view = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreateImageView(device, &view_info, nullptr, &view));
  view_ = UniqueImageView(device, view);
}

}  // namespace relight::vk
