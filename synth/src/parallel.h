#pragma once
// Row-parallel loops for the renderers. Rows are handed out through an atomic counter; since
// each row's result depends only on the row, the output does not depend on the schedule.
#include <functional>

namespace relight::synth::detail {

/// Calls body(row) for every row in [0, rows) on `threads` std::threads (0 = hardware threads).
void parallel_rows(int rows, int threads, const std::function<void(int)>& body);

}  // namespace relight::synth::detail
