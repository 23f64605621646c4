#pragma once
// VulkanContext: the instance, the chosen physical device, a logical device with a compute queue,
// and what every Vulkan stage needs around them (a command pool, memory-type lookup, one-shot
// submission, validation, the frame graph's DeviceTransfer).
//
// Create it with try_create_vulkan(), which returns nullptr (and says why once on stderr) when no
// Vulkan device exists, so that callers fall back to the CPU path:
//
//   std::string why;
//   auto vulkan = relight::vk::try_create_vulkan({}, &why);   // null: run everything on the CPU
//   relight::FrameGraph graph(vulkan ? &vulkan->transfer() : nullptr);
//
// Threading: a context and everything made from it are used from one thread at a time.
// Submission is synchronous (submit() waits for the GPU), which keeps buffer lifetimes trivial;
// batching several stages into one submission is a later optimisation.
#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "relight/vk/device_selection.h"
#include "relight/vk/handles.h"
#include "relight/vk/validation.h"

namespace relight::vk {

class VulkanTransfer;

/// Auto: on in builds without NDEBUG, or when RELIGHT_VK_VALIDATION=1; RELIGHT_VK_VALIDATION=0
/// turns it off. On/Off override the environment. Validation is only ever enabled when the
/// VK_LAYER_KHRONOS_validation layer is installed (otherwise a note goes to stderr).
enum class Validation { Auto, On, Off };

struct VulkanOptions {
  /// Device selector (index, type or name substring; see device_selection.h). Empty: the
  /// environment variable RELIGHT_VK_DEVICE, else the best device.
  std::string device{};
  Validation validation = Validation::Auto;
  /// Treat device memory as if the host could not map it, so that uploads and downloads go
  /// through staging buffers and copy commands: the path a discrete GPU takes. On lavapipe (one
  /// host-visible memory type) this is how tests exercise that path.
  bool force_staging = false;
};

class VulkanContext {
 public:
  /// Throws relight::Error (VulkanError for a failed call) when no usable device can be set up.
  explicit VulkanContext(const VulkanOptions& options = {});
  ~VulkanContext();
  VulkanContext(const VulkanContext&) = delete;
  VulkanContext& operator=(const VulkanContext&) = delete;
  VulkanContext(VulkanContext&&) = delete;  // stages and buffers keep references to it
  VulkanContext& operator=(VulkanContext&&) = delete;

  [[nodiscard]] VkInstance instance() const { return instance_.get(); }
  [[nodiscard]] VkPhysicalDevice physical_device() const { return physical_device_; }
  [[nodiscard]] VkDevice device() const { return device_.get(); }
  [[nodiscard]] const DeviceInfo& device_info() const { return info_; }
  /// True for a software device (lavapipe): per-pixel stages are faster on relight's CPU path.
  [[nodiscard]] bool is_cpu_device() const { return info_.type == DeviceType::Cpu; }
  [[nodiscard]] const VkPhysicalDeviceProperties& properties() const { return properties_; }
  [[nodiscard]] const VkPhysicalDeviceMemoryProperties& memory_properties() const { return memory_properties_; }

  /// Device memory allocations made through this context so far (every VulkanBuffer and
  /// VulkanImage makes one): what the tests count to show that a steady run allocates nothing.
  [[nodiscard]] std::uint64_t memory_allocations() const { return memory_allocations_.load(); }
  /// Called by VulkanBuffer and VulkanImage for each vkAllocateMemory.
  void count_memory_allocation() const { ++memory_allocations_; }

  /// The queue submit() uses: a family with compute (and graphics where one has both).
  [[nodiscard]] VkQueue compute_queue() const { return compute_queue_; }
  [[nodiscard]] std::uint32_t compute_queue_family() const { return compute_family_; }
  /// A graphics-capable queue for the renderer; empty on a compute-only device.
  [[nodiscard]] std::optional<std::uint32_t> graphics_queue_family() const { return graphics_family_; }
  [[nodiscard]] VkQueue graphics_queue() const { return graphics_queue_; }

  /// Whether the compute queue can write timestamps, and nanoseconds per timestamp tick.
  [[nodiscard]] bool timestamps_supported() const { return timestamp_valid_bits_ > 0; }
  [[nodiscard]] std::uint32_t timestamp_valid_bits() const { return timestamp_valid_bits_; }
  [[nodiscard]] double timestamp_period_ns() const { return properties_.limits.timestampPeriod; }

  [[nodiscard]] bool validation_enabled() const { return validation_log_ != nullptr; }
  /// Validation messages so far (null when validation is off). Shared: it outlives the context.
  [[nodiscard]] const std::shared_ptr<ValidationLog>& validation_log() const { return validation_log_; }
  /// Validation errors so far; 0 when validation is off.
  [[nodiscard]] int validation_errors() const { return validation_log_ ? validation_log_->errors() : 0; }

  [[nodiscard]] bool force_staging() const { return force_staging_; }
  /// A memory type index allowed by `type_bits` with all `required` flags, preferring one that
  /// also has all `preferred` flags. Throws relight::Error when none qualifies.
  [[nodiscard]] std::uint32_t find_memory_type(std::uint32_t type_bits, VkMemoryPropertyFlags required,
                                               VkMemoryPropertyFlags preferred) const;

  /// Records `record` into a one-time command buffer, submits it to the compute queue and waits
  /// until it has finished. Full memory barriers before and after the recorded commands make
  /// earlier submissions' and host writes visible to it, and its writes visible to the host;
  /// commands inside one `record` that depend on each other still need their own barriers.
  void submit(const std::function<void(VkCommandBuffer)>& record);

  /// True once a submission returned VK_ERROR_DEVICE_LOST: the device is gone for good (a driver
  /// reset, a GPU fault, an unplugged eGPU) and every later submit() fails the same way at once.
  [[nodiscard]] bool device_lost() const { return device_lost_.load(); }
  /// Test hook for the device-lost fault (the robustness rows, RELIGHT_TEST_DEVICE_LOST_AT_FRAME):
  /// from now on submit() fails with VK_ERROR_DEVICE_LOST as after a real loss. No driver can be
  /// made to lose its device on demand, lavapipe least of all.
  void simulate_device_loss() { device_lost_ = true; }

  /// The frame graph's host<->device mover for this context.
  [[nodiscard]] VulkanTransfer& transfer() { return *transfer_; }

 private:
  mutable std::atomic<std::uint64_t> memory_allocations_{0};
  std::atomic<bool> device_lost_{false};
  void create_instance(bool want_validation);
  void pick_physical_device(const std::string& selector);
  void create_device();

  // Declaration order is destruction order reversed: the instance outlives everything.
  std::shared_ptr<ValidationLog> validation_log_;
  UniqueInstance instance_;
  DebugMessenger messenger_;
  VkPhysicalDevice physical_device_ = VK_NULL_HANDLE;
  DeviceInfo info_;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memory_properties_{};
  std::uint32_t compute_family_ = 0;
  std::optional<std::uint32_t> graphics_family_;
  std::uint32_t timestamp_valid_bits_ = 0;
  bool force_staging_ = false;
  UniqueDevice device_;
  VkQueue compute_queue_ = VK_NULL_HANDLE;
  VkQueue graphics_queue_ = VK_NULL_HANDLE;
  UniqueCommandPool command_pool_;
  UniqueFence fence_;
  std::unique_ptr<VulkanTransfer> transfer_;
};

/// Creates a context, or returns nullptr when none can be created (no driver, no device, the
/// selector matched nothing). The reason goes to `*why` when given and, once per process, to
/// stderr, so that "no Vulkan, using the CPU path" is visible without flooding the log.
[[nodiscard]] std::unique_ptr<VulkanContext> try_create_vulkan(const VulkanOptions& options = {},
                                                              std::string* why = nullptr);

}  // namespace relight::vk
