#pragma once
// The frame graph's view of a compute device: it can allocate device buffers and copy bytes in
// and out. The Vulkan context implements this (relight_vk); core itself includes no Vulkan
// headers. A Vulkan stage asks the graph for the device copy of a buffer; the graph uploads or
// downloads only when the other side holds the newer data.
#include <cstddef>
#include <memory>
#include <span>

namespace relight {

class DeviceBuffer {
 public:
  virtual ~DeviceBuffer() = default;
  [[nodiscard]] virtual std::size_t size_bytes() const = 0;
};

class DeviceTransfer {
 public:
  virtual ~DeviceTransfer() = default;
  [[nodiscard]] virtual std::unique_ptr<DeviceBuffer> allocate(std::size_t bytes) = 0;
  virtual void upload(std::span<const std::byte> source, DeviceBuffer& destination) = 0;
  virtual void download(const DeviceBuffer& source, std::span<std::byte> destination) = 0;
};

}  // namespace relight
