#include "relight/vk/context.h"

#include <cstdlib>
#include <cstring>
#include <iostream>
#include <mutex>
#include <vector>

#include "relight/vk/check.h"
#include "relight/vk/transfer.h"

namespace relight::vk {

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
// Long enough for a slow software device, short enough that a hung GPU fails a run.
constexpr std::uint64_t kSubmitTimeoutNs = 120'000'000'000ull;

bool env_is(const char* name, const char* value) {
  const char* set = std::getenv(name);
  return set != nullptr && std::strcmp(set, value) == 0;
}

bool wants_validation(Validation validation) {
  if (validation != Validation::Auto) return validation == Validation::On;
  if (env_is("RELIGHT_VK_VALIDATION", "1")) return true;
  if (env_is("RELIGHT_VK_VALIDATION", "0")) return false;
#ifdef NDEBUG
  return false;
#else
  return true;
#endif
}

bool layer_available(const char* layer) {
  std::uint32_t count = 0;
  RELIGHT_VK_CHECK(vkEnumerateInstanceLayerProperties(&count, nullptr));
  std::vector<VkLayerProperties> layers(count);
  RELIGHT_VK_CHECK(vkEnumerateInstanceLayerProperties(&count, layers.data()));
  for (const auto& properties : layers) {
    if (std::strcmp(properties.layerName, layer) == 0) return true;
  }
  return false;
}

DeviceType device_type(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return DeviceType::Discrete;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return DeviceType::Integrated;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return DeviceType::Virtual;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return DeviceType::Cpu;
    default: return DeviceType::Other;
  }
}

std::vector<VkQueueFamilyProperties> queue_families(VkPhysicalDevice device) {
  std::uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
  return families;
}

// A family with compute, preferring one that also has graphics: on most GPUs that is the
// "universal" family, which always supports timestamps.
std::optional<std::uint32_t> find_compute_family(const std::vector<VkQueueFamilyProperties>& families) {
  std::optional<std::uint32_t> compute;
  for (std::uint32_t i = 0; i < families.size(); ++i) {
    const VkQueueFlags flags = families[i].queueFlags;
    if (!(flags & VK_QUEUE_COMPUTE_BIT) || families[i].queueCount == 0) continue;
    if (flags & VK_QUEUE_GRAPHICS_BIT) return i;
    if (!compute) compute = i;
  }
  return compute;
}

std::optional<std::uint32_t> find_graphics_family(const std::vector<VkQueueFamilyProperties>& families) {
  for (std::uint32_t i = 0; i < families.size(); ++i) {
    if ((families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) && families[i].queueCount > 0) return i;
  }
  return std::nullopt;
}

DeviceInfo describe(VkPhysicalDevice device) {
  VkPhysicalDeviceProperties properties{};
  vkGetPhysicalDeviceProperties(device, &properties);
  DeviceInfo info;
  info.name = properties.deviceName;
  info.type = device_type(properties.deviceType);
  info.api_version = properties.apiVersion;
  if (properties.apiVersion < VK_API_VERSION_1_1) {
    info.usable = false;
    info.unusable_reason = "Vulkan 1.1 required";
  } else if (!find_compute_family(queue_families(device))) {
    info.usable = false;
    info.unusable_reason = "no compute queue";
  }
  return info;
}

}  // namespace

VulkanContext::VulkanContext(const VulkanOptions& options) : force_staging_(options.force_staging) {
  create_instance(wants_validation(options.validation));
  std::string selector = options.device;
  if (selector.empty()) {
    if (const char* env = std::getenv("RELIGHT_VK_DEVICE")) selector = env;
  }
  pick_physical_device(selector);
  create_device();
  transfer_ = std::make_unique<VulkanTransfer>(*this);
}

VulkanContext::~VulkanContext() {
  // Nothing may still run on the GPU while its objects are destroyed; submit() always waits, so
  // this only matters after an exception interrupted a submission.
  if (device_.get() != VK_NULL_HANDLE) (void)vkDeviceWaitIdle(device_.get());
}

void VulkanContext::create_instance(bool want_validation) {
  bool validation = false;
  if (want_validation) {
    validation = layer_available(kValidationLayer);
    if (!validation) std::cerr << "relight: Vulkan validation requested but " << kValidationLayer << " is not installed\n";
  }

  std::uint32_t loader_version = VK_API_VERSION_1_0;
  RELIGHT_VK_CHECK(vkEnumerateInstanceVersion(&loader_version));
  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "relight";
  app.pEngineName = "relight";
  // The highest version relight may use; devices below it still enumerate (Vulkan >= 1.1 loaders).
  app.apiVersion = loader_version < VK_API_VERSION_1_3 ? loader_version : VK_API_VERSION_1_3;

  std::vector<const char*> layers;
  std::vector<const char*> extensions;
  if (validation) {
    validation_log_ = std::make_shared<ValidationLog>();
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);  // provided by the validation layer
  }
  VkInstanceCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  info.pApplicationInfo = &app;
  info.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  const auto messenger_info = DebugMessenger::create_info(validation_log_.get());
  if (validation) info.pNext = &messenger_info;

  VkInstance instance = VK_NULL_HANDLE;
  if (validation) validation_log_->hold();
  const VkResult result = vkCreateInstance(&info, nullptr, &instance);
  if (validation) validation_log_->release(result == VK_SUCCESS);
  if (result == VK_ERROR_INCOMPATIBLE_DRIVER) {
    // What the loader says when it finds no driver at all: say that in words.
    throw VulkanError(result, "no Vulkan driver found (vkCreateInstance: VK_ERROR_INCOMPATIBLE_DRIVER); "
                              "mesa-vulkan-drivers provides the lavapipe CPU device");
  }
  RELIGHT_VK_CHECK(result);
  instance_ = UniqueInstance(instance);
  if (validation) messenger_ = DebugMessenger(instance, validation_log_);
}

void VulkanContext::pick_physical_device(const std::string& selector) {
  std::uint32_t count = 0;
  RELIGHT_VK_CHECK(vkEnumeratePhysicalDevices(instance_.get(), &count, nullptr));
  std::vector<VkPhysicalDevice> devices(count);
  if (count > 0) RELIGHT_VK_CHECK(vkEnumeratePhysicalDevices(instance_.get(), &count, devices.data()));
  devices.resize(count);

  std::vector<DeviceInfo> infos;
  for (VkPhysicalDevice device : devices) infos.push_back(describe(device));
  const std::size_t chosen = choose_physical_device(infos, selector);
  physical_device_ = devices[chosen];
  info_ = infos[chosen];
  vkGetPhysicalDeviceProperties(physical_device_, &properties_);
  vkGetPhysicalDeviceMemoryProperties(physical_device_, &memory_properties_);

  const auto families = queue_families(physical_device_);
  compute_family_ = *find_compute_family(families);  // describe() made sure there is one
  graphics_family_ = find_graphics_family(families);
  // timestampPeriod 0 would make every reading 0 ms; treat it as "no timestamps".
  if (properties_.limits.timestampPeriod > 0.f) timestamp_valid_bits_ = families[compute_family_].timestampValidBits;
}

void VulkanContext::create_device() {
  const float priority = 1.f;
  std::vector<VkDeviceQueueCreateInfo> queues;
  auto add_queue = [&](std::uint32_t family) {
    VkDeviceQueueCreateInfo queue{};
    queue.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    queue.queueFamilyIndex = family;
    queue.queueCount = 1;
    queue.pQueuePriorities = &priority;
    queues.push_back(queue);
  };
  add_queue(compute_family_);
  if (graphics_family_ && *graphics_family_ != compute_family_) add_queue(*graphics_family_);

  VkDeviceCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  info.queueCreateInfoCount = static_cast<std::uint32_t>(queues.size());
  info.pQueueCreateInfos = queues.data();
  VkDevice device = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreateDevice(physical_device_, &info, nullptr, &device));
  device_ = UniqueDevice(device);
  vkGetDeviceQueue(device, compute_family_, 0, &compute_queue_);
  if (graphics_family_) vkGetDeviceQueue(device, *graphics_family_, 0, &graphics_queue_);

  VkCommandPoolCreateInfo pool_info{};
  pool_info.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  pool_info.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
  pool_info.queueFamilyIndex = compute_family_;
  VkCommandPool pool = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreateCommandPool(device, &pool_info, nullptr, &pool));
  command_pool_ = UniqueCommandPool(device, pool);

  VkFenceCreateInfo fence_info{};
  fence_info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  VkFence fence = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreateFence(device, &fence_info, nullptr, &fence));
  fence_ = UniqueFence(device, fence);
}

std::uint32_t VulkanContext::find_memory_type(std::uint32_t type_bits, VkMemoryPropertyFlags required,
                                              VkMemoryPropertyFlags preferred) const {
  std::optional<std::uint32_t> fallback;
  for (std::uint32_t i = 0; i < memory_properties_.memoryTypeCount; ++i) {
    const VkMemoryPropertyFlags flags = memory_properties_.memoryTypes[i].propertyFlags;
    if (!(type_bits & (1u << i)) || (flags & required) != required) continue;
    if ((flags & preferred) == preferred) return i;
    if (!fallback) fallback = i;
  }
  if (!fallback) throw Error("Vulkan device '" + info_.name + "' has no memory type with the required properties");
  return *fallback;
}

namespace {
// Makes every earlier write (host or device) visible to every later access, including host reads.
void full_barrier(VkCommandBuffer cmd, VkPipelineStageFlags destination_stages, VkAccessFlags destination_access) {
  VkMemoryBarrier barrier{};
  barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  barrier.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
  barrier.dstAccessMask = destination_access;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, destination_stages, 0, 1, &barrier, 0, nullptr, 0,
                       nullptr);
}
}  // namespace

void VulkanContext::submit(const std::function<void(VkCommandBuffer)>& record) {
  if (device_lost_) throw_vulkan_error(VK_ERROR_DEVICE_LOST, "vkQueueSubmit", __FILE__, __LINE__);
  VkCommandBufferAllocateInfo allocate{};
  allocate.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  allocate.commandPool = command_pool_.get();
  allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  allocate.commandBufferCount = 1;
  VkCommandBuffer raw = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkAllocateCommandBuffers(device_.get(), &allocate, &raw));
  const UniqueCommandBuffer cmd(device_.get(), command_pool_.get(), raw);

  VkCommandBufferBeginInfo begin{};
  begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  RELIGHT_VK_CHECK(vkBeginCommandBuffer(raw, &begin));
  full_barrier(raw, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT);
  record(raw);
  full_barrier(raw, VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
  RELIGHT_VK_CHECK(vkEndCommandBuffer(raw));

  VkSubmitInfo submit_info{};
  submit_info.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  submit_info.commandBufferCount = 1;
  submit_info.pCommandBuffers = &raw;
  VkFence fence = fence_.get();
  VkResult result = vkQueueSubmit(compute_queue_, 1, &submit_info, fence);
  if (result == VK_SUCCESS) result = vkWaitForFences(device_.get(), 1, &fence, VK_TRUE, kSubmitTimeoutNs);
  if (result == VK_ERROR_DEVICE_LOST) device_lost_ = true;
  if (result != VK_SUCCESS) throw_vulkan_error(result, "vkQueueSubmit/vkWaitForFences", __FILE__, __LINE__);
  RELIGHT_VK_CHECK(vkResetFences(device_.get(), 1, &fence));
}

std::unique_ptr<VulkanContext> try_create_vulkan(const VulkanOptions& options, std::string* why) {
  try {
    return std::make_unique<VulkanContext>(options);
  } catch (const Error& error) {
    if (why) *why = error.what();
    static std::once_flag said_once;
    std::call_once(said_once, [&] {
      std::cerr << "relight: warning: no usable Vulkan device, using the CPU path: " << error.what() << '\n';
    });
    return nullptr;
  }
}

}  // namespace relight::vk
