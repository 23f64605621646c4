#pragma once
// VulkanImage: a 2D VkImage with its own device-local memory and one view of the whole image
// (render targets, shadow maps).
#include <vulkan/vulkan.h>

#include <cstdint>

#include "relight/vk/handles.h"

namespace relight::vk {

class VulkanContext;

class VulkanImage {
 public:
  /// `aspect` selects the view's aspect (colour or depth).
  VulkanImage(const VulkanContext& context, std::uint32_t width, std::uint32_t height, VkFormat format,
              VkImageUsageFlags usage, VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT);

  [[nodiscard]] VkImage handle() const { return image_.get(); }
  [[nodiscard]] VkImageView view() const { return view_.get(); }
  [[nodiscard]] VkFormat format() const { return format_; }
  [[nodiscard]] std::uint32_t width() const { return width_; }
  [[nodiscard]] std::uint32_t height() const { return height_; }

 private:
  UniqueMemory memory_;  // declared first: the image and view go before their memory
  UniqueImage image_;
  UniqueImageView view_;
  VkFormat format_;
  std::uint32_t width_, height_;
};

}  // namespace relight::vk
