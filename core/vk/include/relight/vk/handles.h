#pragma once
// Move-only RAII owners for raw Vulkan handles. Each owner destroys its handle exactly once, in
// its destructor (there is no destroy() to call by hand); moving transfers ownership and leaves
// the source empty. Owners do not keep their parent alive: declare parents before children so
// that C++'s reverse destruction order tears them down correctly (VulkanContext does so).
#include <vulkan/vulkan.h>

#include <utility>

namespace relight::vk {

/// Owner of a handle created from a VkDevice and destroyed with `vkDestroyX(device, handle, nullptr)`.
/// Destroy is the loader's function, e.g. vkDestroyBuffer; vkFreeMemory has the same shape.
template <class Handle, auto Destroy>
class DeviceObject {
 public:
  DeviceObject() = default;
  DeviceObject(VkDevice device, Handle handle) noexcept : device_(device), handle_(handle) {}
  ~DeviceObject() { reset(); }
  DeviceObject(const DeviceObject&) = delete;
  DeviceObject& operator=(const DeviceObject&) = delete;
  DeviceObject(DeviceObject&& other) noexcept
      : device_(other.device_), handle_(std::exchange(other.handle_, Handle{VK_NULL_HANDLE})) {}
  DeviceObject& operator=(DeviceObject&& other) noexcept {
    if (this != &other) {
      reset();
      device_ = other.device_;
      handle_ = std::exchange(other.handle_, Handle{VK_NULL_HANDLE});
    }
    return *this;
  }

  [[nodiscard]] Handle get() const { return handle_; }
  [[nodiscard]] VkDevice device() const { return device_; }
  explicit operator bool() const { return handle_ != VK_NULL_HANDLE; }

 private:
  void reset() noexcept {
    if (handle_ != VK_NULL_HANDLE) Destroy(device_, handle_, nullptr);
    handle_ = VK_NULL_HANDLE;
  }
  VkDevice device_ = VK_NULL_HANDLE;
  Handle handle_ = VK_NULL_HANDLE;
};

using UniqueBuffer = DeviceObject<VkBuffer, vkDestroyBuffer>;
using UniqueMemory = DeviceObject<VkDeviceMemory, vkFreeMemory>;
using UniqueImage = DeviceObject<VkImage, vkDestroyImage>;
using UniqueImageView = DeviceObject<VkImageView, vkDestroyImageView>;
using UniqueSampler = DeviceObject<VkSampler, vkDestroySampler>;
using UniqueShaderModule = DeviceObject<VkShaderModule, vkDestroyShaderModule>;
using UniquePipeline = DeviceObject<VkPipeline, vkDestroyPipeline>;
using UniquePipelineLayout = DeviceObject<VkPipelineLayout, vkDestroyPipelineLayout>;
using UniqueDescriptorSetLayout = DeviceObject<VkDescriptorSetLayout, vkDestroyDescriptorSetLayout>;
using UniqueDescriptorPool = DeviceObject<VkDescriptorPool, vkDestroyDescriptorPool>;
using UniqueCommandPool = DeviceObject<VkCommandPool, vkDestroyCommandPool>;
using UniqueFence = DeviceObject<VkFence, vkDestroyFence>;
using UniqueSemaphore = DeviceObject<VkSemaphore, vkDestroySemaphore>;
using UniqueQueryPool = DeviceObject<VkQueryPool, vkDestroyQueryPool>;
using UniqueRenderPass = DeviceObject<VkRenderPass, vkDestroyRenderPass>;
using UniqueFramebuffer = DeviceObject<VkFramebuffer, vkDestroyFramebuffer>;

/// Owner of a handle allocated from a pool (command buffers, descriptor sets) and given back with
/// `vkFreeX(device, pool, 1, &handle)`. Descriptor pools must have
/// VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT for this.
template <class Handle, class Pool, auto Free>
class PoolObject {
 public:
  PoolObject() = default;
  PoolObject(VkDevice device, Pool pool, Handle handle) noexcept : device_(device), pool_(pool), handle_(handle) {}
  ~PoolObject() { reset(); }
  PoolObject(const PoolObject&) = delete;
  PoolObject& operator=(const PoolObject&) = delete;
  PoolObject(PoolObject&& other) noexcept
      : device_(other.device_), pool_(other.pool_), handle_(std::exchange(other.handle_, Handle{VK_NULL_HANDLE})) {}
  PoolObject& operator=(PoolObject&& other) noexcept {
    if (this != &other) {
      reset();
      device_ = other.device_;
      pool_ = other.pool_;
      handle_ = std::exchange(other.handle_, Handle{VK_NULL_HANDLE});
    }
    return *this;
  }

  [[nodiscard]] Handle get() const { return handle_; }
  explicit operator bool() const { return handle_ != VK_NULL_HANDLE; }

 private:
  void reset() noexcept {
    if (handle_ != VK_NULL_HANDLE) (void)Free(device_, pool_, 1, &handle_);
    handle_ = VK_NULL_HANDLE;
  }
  VkDevice device_ = VK_NULL_HANDLE;
  Pool pool_ = VK_NULL_HANDLE;
  Handle handle_ = VK_NULL_HANDLE;
};

using UniqueCommandBuffer = PoolObject<VkCommandBuffer, VkCommandPool, vkFreeCommandBuffers>;
using UniqueDescriptorSet = PoolObject<VkDescriptorSet, VkDescriptorPool, vkFreeDescriptorSets>;

/// Owns a VkInstance (vkDestroyInstance).
class UniqueInstance {
 public:
  UniqueInstance() = default;
  explicit UniqueInstance(VkInstance instance) noexcept : instance_(instance) {}
  ~UniqueInstance() {
    if (instance_ != VK_NULL_HANDLE) vkDestroyInstance(instance_, nullptr);
  }
  UniqueInstance(const UniqueInstance&) = delete;
  UniqueInstance& operator=(const UniqueInstance&) = delete;
  UniqueInstance(UniqueInstance&& other) noexcept : instance_(std::exchange(other.instance_, VK_NULL_HANDLE)) {}
  UniqueInstance& operator=(UniqueInstance&& other) noexcept {
    std::swap(instance_, other.instance_);
    return *this;
  }
  [[nodiscard]] VkInstance get() const { return instance_; }

 private:
  VkInstance instance_ = VK_NULL_HANDLE;
};

/// Owns a VkDevice (vkDestroyDevice). Every DeviceObject made from it must be gone first.
class UniqueDevice {
 public:
  UniqueDevice() = default;
  explicit UniqueDevice(VkDevice device) noexcept : device_(device) {}
  ~UniqueDevice() {
    if (device_ != VK_NULL_HANDLE) vkDestroyDevice(device_, nullptr);
  }
  UniqueDevice(const UniqueDevice&) = delete;
  UniqueDevice& operator=(const UniqueDevice&) = delete;
  UniqueDevice(UniqueDevice&& other) noexcept : device_(std::exchange(other.device_, VK_NULL_HANDLE)) {}
  UniqueDevice& operator=(UniqueDevice&& other) noexcept {
    std::swap(device_, other.device_);
    return *this;
  }
  [[nodiscard]] VkDevice get() const { return device_; }

 private:
  VkDevice device_ = VK_NULL_HANDLE;
};

}  // namespace relight::vk
