// The Vulkan layer on whatever device this machine has (lavapipe in CI): device found, bytes
// survive host<->device transfers on both the mapped and the staging path, timestamps measure
// something, RAII leaves nothing behind, and validation errors are counted.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include <numeric>
#include <vector>

#include "relight/vk/backend.h"
#include "relight/vk/buffer.h"
#include "relight/vk/check.h"
#include "relight/vk/compute_pipeline.h"
#include "relight/vk/image.h"
#include "relight/vk/timer.h"
#include "relight/vk/transfer.h"
#include "relight/shaders/add_constant_test_comp.h"
#include "support/vulkan_test_env.h"

namespace relight::vk {
namespace {

using VulkanContextTest = test::VulkanTest;

std::vector<std::byte> pattern(std::size_t n) {
  std::vector<std::byte> bytes(n);
  for (std::size_t i = 0; i < n; ++i) bytes[i] = static_cast<std::byte>((i * 131 + 7) & 0xff);
  return bytes;
}

void expect_round_trip(VulkanContext& context, std::size_t n) {
  const auto source = pattern(n);
  auto buffer = context.transfer().allocate(n);
  ASSERT_EQ(buffer->size_bytes(), n);
  context.transfer().upload(source, *buffer);
  std::vector<std::byte> back(n, std::byte{0});
  context.transfer().download(*buffer, back);
  EXPECT_EQ(back, source);
}

TEST_F(VulkanContextTest, FindsADeviceWithAComputeQueue) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  EXPECT_FALSE(context.device_info().name.empty());
  EXPECT_NE(context.device(), VK_NULL_HANDLE);
  EXPECT_NE(context.compute_queue(), VK_NULL_HANDLE);
  EXPECT_GE(context.device_info().api_version, VK_API_VERSION_1_1);
  if (context.graphics_queue_family()) {
    EXPECT_NE(context.graphics_queue(), VK_NULL_HANDLE);
  }
  std::cout << "[          ] device: " << context.device_info().name << " [" << to_string(context.device_info().type)
            << "], validation " << (context.validation_enabled() ? "on" : "off") << '\n';
}

TEST_F(VulkanContextTest, UploadDownloadRoundTripOnTheDefaultPath) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  expect_round_trip(context, 1001);  // odd size: nothing assumes multiples of 4
  expect_round_trip(context, 640 * 480 * 4);
  expect_round_trip(context, 0);
}

TEST_F(VulkanContextTest, UploadDownloadRoundTripThroughStagingBuffers) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(shared);
  (void)shared;
  auto context = try_create_vulkan({.validation = Validation::On, .force_staging = true});
  ASSERT_NE(context, nullptr);
  VulkanBuffer buffer(*context, 16);
  EXPECT_FALSE(buffer.host_mapped());  // so the transfers below use copy commands
  expect_round_trip(*context, 1001);
  expect_round_trip(*context, 640 * 480 * 4);
  expect_round_trip(*context, 12);  // smaller than the cached staging buffers
  EXPECT_EQ(context->validation_errors(), 0) << context->validation_log()->summary();
}

TEST_F(VulkanContextTest, TimestampQueryMeasuresAPositiveTime) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  ASSERT_TRUE(context.timestamps_supported());
  EXPECT_GT(context.timestamp_period_ns(), 0.0);
  VulkanBuffer buffer(context, 64u << 20);
  GpuTimer timer(context);
  EXPECT_EQ(timer.elapsed_ms(), std::nullopt);  // nothing recorded yet
  context.submit([&](VkCommandBuffer cmd) {
    timer.start(cmd);
    vkCmdFillBuffer(cmd, buffer.handle(), 0, VK_WHOLE_SIZE, 0x3f800000u);
    timer.stop(cmd);
  });
  const auto ms = timer.elapsed_ms();
  ASSERT_TRUE(ms.has_value());
  EXPECT_GT(*ms, 0.0);
  EXPECT_LT(*ms, 60'000.0);
}

// A shader embedded by relight_embed_shaders, run through ComputePipeline on mapped buffers.
TEST_F(VulkanContextTest, ComputePipelineRunsAnEmbeddedShader) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  struct Params {
    std::uint32_t count;
    float add;
  };
  constexpr std::uint32_t n = 1000;  // not a multiple of the work-group size
  std::vector<float> values(n);
  std::iota(values.begin(), values.end(), 0.f);
  VulkanBuffer input(context, n * sizeof(float)), output(context, n * sizeof(float));
  context.transfer().upload(std::as_bytes(std::span(values)), input);
  ComputePipeline pipeline(context, {.spirv = shaders::add_constant_test_comp, .storage_buffers = 2,
                                     .push_constant_bytes = sizeof(Params)});
  const auto set = pipeline.bind({&input, &output});
  context.submit([&](VkCommandBuffer cmd) {
    pipeline.dispatch(cmd, set, Params{n, 0.5f}, ComputePipeline::group_count(n, 64), 1);
  });
  std::vector<float> result(n);
  context.transfer().download(output, std::as_writable_bytes(std::span(result)));
  for (std::uint32_t i = 0; i < n; ++i) ASSERT_EQ(result[i], static_cast<float>(i) + 0.5f) << i;
  EXPECT_THROW(pipeline.dispatch(VK_NULL_HANDLE, set, 1.f, 1, 1), LogicError);  // wrong push-constant size
  EXPECT_THROW((void)pipeline.bind({&input}), LogicError);
}

// A lost device fails every later submission at once with VK_ERROR_DEVICE_LOST (no wait, no
// hang), and the context says so; its own context, as the loss is for good.
TEST_F(VulkanContextTest, ALostDeviceFailsEverySubmissionAtOnce) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(shared);
  (void)shared;
  auto context = try_create_vulkan({.validation = Validation::On});
  ASSERT_NE(context, nullptr);
  expect_round_trip(*context, 64);
  EXPECT_FALSE(context->device_lost());
  context->simulate_device_loss();
  EXPECT_TRUE(context->device_lost());
  for (int attempt = 0; attempt < 2; ++attempt) {
    bool recorded = false;
    try {
      context->submit([&](VkCommandBuffer) { recorded = true; });
      ADD_FAILURE() << "submit() after the loss returned";
    } catch (const VulkanError& e) {
      EXPECT_EQ(e.result(), VK_ERROR_DEVICE_LOST);
      EXPECT_NE(std::string(e.what()).find("VK_ERROR_DEVICE_LOST"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(recorded);  // nothing is recorded for a device that is gone
  }
  EXPECT_EQ(context->validation_errors(), 0) << context->validation_log()->summary();
}

TEST_F(VulkanContextTest, TransferRejectsForeignBuffers) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  struct Foreign final : DeviceBuffer {
    std::size_t size_bytes() const override { return 4; }
  } foreign;
  const auto bytes = pattern(4);
  EXPECT_THROW(context.transfer().upload(bytes, foreign), LogicError);
  auto small = context.transfer().allocate(2);
  EXPECT_THROW(context.transfer().upload(bytes, *small), LogicError);
}

TEST(VulkanCheck, ThrowsWithCallResultNameAndLocation) {
  try {
    RELIGHT_VK_CHECK(VK_ERROR_DEVICE_LOST);
    FAIL() << "expected VulkanError";
  } catch (const VulkanError& e) {
    const std::string message = e.what();
    EXPECT_EQ(e.result(), VK_ERROR_DEVICE_LOST);
    EXPECT_NE(message.find("VK_ERROR_DEVICE_LOST failed with VK_ERROR_DEVICE_LOST"), std::string::npos) << message;
    EXPECT_NE(message.find("vulkan_context_test.cpp:"), std::string::npos) << message;
  }
  EXPECT_EQ(result_name(static_cast<VkResult>(-12345)), "VkResult(-12345)");
}

TEST(VulkanContextCreation, UnknownSelectorGivesNullAndTheReason) {
  std::string why;
  auto context = try_create_vulkan({.device = "no-such-gpu", .validation = Validation::Off}, &why);
  EXPECT_EQ(context, nullptr);
  EXPECT_FALSE(why.empty());
  if (test::shared_vulkan().context) {
    EXPECT_NE(why.find("'no-such-gpu'"), std::string::npos) << why;
  }
}

// The validation tests need VK_LAYER_KHRONOS_validation (Debian: vulkan-validationlayers). Where
// it is not installed (e.g. a GPU machine with only the driver) they skip, unless
// RELIGHT_REQUIRE_VALIDATION=1 (scripts/test.sh, CI) makes that a failure.
bool validation_required() {
  const char* env = std::getenv("RELIGHT_REQUIRE_VALIDATION");
  return env != nullptr && std::string(env) == "1";
}

#define RELIGHT_REQUIRE_VALIDATION_LAYER(context)                                                   \
  if (!(context).validation_enabled()) {                                                            \
    if (validation_required()) FAIL() << "RELIGHT_REQUIRE_VALIDATION=1 but the validation layer is missing"; \
    GTEST_SKIP() << "VK_LAYER_KHRONOS_validation is not installed";                                 \
  }

// Creates one of each wrapped object; the validation layer reports any left alive when the
// device is destroyed, and the shared log outlives the context to catch exactly that.
TEST(VulkanRaii, EveryWrapperReleasesItsObject) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(shared);
  (void)shared;
  std::shared_ptr<ValidationLog> log;
  {
    VulkanContext context({.validation = Validation::On});
    RELIGHT_REQUIRE_VALIDATION_LAYER(context);
    log = context.validation_log();
    const VkDevice device = context.device();

    VulkanBuffer a(context, 256), b(context, 256);
    VulkanBuffer moved = std::move(b);
    ComputePipeline pipeline(context, {.spirv = shaders::add_constant_test_comp, .storage_buffers = 2,
                                       .push_constant_bytes = 8});
    const auto set = pipeline.bind({&a, &moved});
    GpuTimer timer(context);

    // Owns a VkImage, its VkDeviceMemory and a VkImageView (UniqueImage/UniqueMemory/UniqueImageView).
    const VulkanImage image(context, 8, 8, VK_FORMAT_R32_SFLOAT, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT);
    EXPECT_NE(image.view(), VK_NULL_HANDLE);

    VkSemaphoreCreateInfo semaphore_info{};
    semaphore_info.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
    VkSemaphore raw_semaphore = VK_NULL_HANDLE;
    RELIGHT_VK_CHECK(vkCreateSemaphore(device, &semaphore_info, nullptr, &raw_semaphore));
    UniqueSemaphore semaphore(device, raw_semaphore);
    UniqueSemaphore semaphore_moved;
    semaphore_moved = std::move(semaphore);
    EXPECT_FALSE(semaphore);
    EXPECT_TRUE(semaphore_moved);
  }
  EXPECT_EQ(log->errors(), 0) << log->summary();
}

TEST(VulkanValidation, ErrorsAreCountedNotJustPrinted) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(shared);
  (void)shared;
  std::shared_ptr<ValidationLog> log;
  {
    VulkanContext context({.validation = Validation::On});
    RELIGHT_REQUIRE_VALIDATION_LAYER(context);
    log = context.validation_log();
    // Deliberately leak a fence (no RAII owner): destroying the device with it alive is a
    // validation error, which must show up in the count.
    VkFenceCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    VkFence leaked = VK_NULL_HANDLE;
    RELIGHT_VK_CHECK(vkCreateFence(context.device(), &info, nullptr, &leaked));
    std::cout << "[          ] (a validation error about a leaked VkFence is expected below)\n";
  }
  EXPECT_GE(log->errors(), 1);
}

TEST(VulkanValidation, HeldMessagesAreRecordedOrDroppedOnRelease) {
  constexpr auto kError = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  ValidationLog log;
  log.hold();
  log.record(kError, "held, then recorded (expected)");
  EXPECT_EQ(log.errors(), 0);
  log.release(true);
  EXPECT_EQ(log.errors(), 1);
  EXPECT_EQ(log.recent_errors().back(), "held, then recorded (expected)");
  log.hold();
  log.record(kError, "held, then dropped");
  log.release(false);
  log.record(kError, "recorded at once (expected)");
  EXPECT_EQ(log.errors(), 2);
  EXPECT_EQ(log.recent_errors().back(), "recorded at once (expected)");
}

TEST_F(VulkanContextTest, BackendPolicyOnThisDevice) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const Backend per_pixel = choose_backend(StageKind::PerPixel, &context);
  EXPECT_EQ(per_pixel, context.is_cpu_device() ? Backend::Cpu : Backend::Vulkan);
  EXPECT_EQ(choose_backend(StageKind::Rasterisation, &context), Backend::Vulkan);
  EXPECT_EQ(choose_backend(StageKind::PerPixel, &context, BackendPolicy::ForceVulkan), Backend::Vulkan);
  EXPECT_EQ(choose_backend(StageKind::Rasterisation, &context, BackendPolicy::ForceCpu), Backend::Cpu);
}

}  // namespace
}  // namespace relight::vk
