#pragma once
// A source of one value that does not change over the run (e.g. the measured light set when it
// comes from a file rather than from a stage), written into the graph every frame.
// Writes: the buffer named at construction.
#include <string>

#include "relight/core/frame_graph.h"

namespace relight::app {

template <class T>
class ConstantStage final : public Stage {
 public:
  ConstantStage(BufferName<T> buffer, T value) : buffer_name_(buffer), value_(std::move(value)) {}
  [[nodiscard]] std::string name() const override { return "constant_" + std::string(buffer_name_.name()); }
  void declare(StageBuilder& builder) override { buffer_ = builder.write(buffer_name_); }
  void run(StageContext& context) override { context.get(buffer_) = value_; }

 private:
  BufferName<T> buffer_name_;
  T value_;
  Write<T> buffer_;
};

}  // namespace relight::app
