#pragma once
// keep_freed_memory_for_reuse(): the pipeline allocates the same large buffers every frame (a
// 640x480 radiance image is 3.7 MB, the shadow-map atlas 16 MB, DIR's shading scratch 16 MB).
// glibc serves such sizes with fresh mmap()s and gives them back on free, so every frame pays a
// page fault per 4 KiB page of each - which on a virtual machine costs far more than the memcpy
// itself: reading the shadow atlas back took 95 ms, 4 ms with the pages kept (bench
// dir/frame_640x480_64vpl on this 2-core VM). Called once at the start of the programs (relight,
// relight-bench); memory stays at its high-water mark instead of shrinking between frames.
namespace relight {

/// Allocations up to 32 MB (glibc's largest mmap threshold) come from the heap, and up to
/// 256 MB of freed heap is kept; no effect without glibc.
void keep_freed_memory_for_reuse();

}  // namespace relight
