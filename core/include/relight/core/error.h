#pragma once
// Two kinds of failure, following the split used throughout relight:
//  - relight::Error: expected run-time failures (bad input file, missing device). The CLI prints
//    what() as one line and exits non-zero. Messages name the file/line/stage involved.
//  - relight::LogicError: programmer or configuration mistakes detected up front (a malformed
//    frame graph); thrown when the graph is compiled, before any frame runs.
#include <stdexcept>
#include <string>

namespace relight {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class LogicError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

}  // namespace relight
