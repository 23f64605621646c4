#pragma once
// Vulkan availability for tests. One validated context is shared by the whole test process
// (creating an instance per test would dominate the run time on lavapipe).
//
// No device: the test FAILs when RELIGHT_REQUIRE_VULKAN=1 (CI, where lavapipe is always
// installed) and is skipped with the reason otherwise, so a skip never looks like a pass.
// VulkanTest checks after every test that the validation layer reported no new error.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>

#include "relight/vk/context.h"

namespace relight::test {

inline bool vulkan_required() {
  const char* env = std::getenv("RELIGHT_REQUIRE_VULKAN");
  return env != nullptr && std::strcmp(env, "1") == 0;
}

struct SharedVulkan {
  std::unique_ptr<vk::VulkanContext> context;
  std::string why;
};

inline SharedVulkan& shared_vulkan() {
  static SharedVulkan shared = [] {
    SharedVulkan s;
    s.context = vk::try_create_vulkan({.validation = vk::Validation::On}, &s.why);
    return s;
  }();
  return shared;
}

class VulkanTest : public ::testing::Test {
 protected:
  void SetUp() override { errors_before_ = shared_vulkan().context ? shared_vulkan().context->validation_errors() : 0; }
  void TearDown() override {
    if (const auto& context = shared_vulkan().context) {
      EXPECT_EQ(context->validation_errors(), errors_before_)
          << "Vulkan validation errors:\n" << context->validation_log()->summary();
    }
  }

 private:
  int errors_before_ = 0;
};

}  // namespace relight::test

/// Declares `vk::VulkanContext& name` for the shared context, or fails/skips the test (see above).
#define RELIGHT_REQUIRE_VULKAN_CONTEXT(name)                                                           \
  if (!::relight::test::shared_vulkan().context) {                                                    \
    if (::relight::test::vulkan_required()) {                                                          \
      FAIL() << "RELIGHT_REQUIRE_VULKAN=1 but no Vulkan device: " << ::relight::test::shared_vulkan().why; \
    }                                                                                                  \
    GTEST_SKIP() << "no Vulkan device: " << ::relight::test::shared_vulkan().why;                      \
  }                                                                                                    \
  ::relight::vk::VulkanContext& name = *::relight::test::shared_vulkan().context
