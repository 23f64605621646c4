#pragma once
// A small tmpfs mounted by a robustness row over its output folder, to fill a disk on purpose
// (root only: a row on a machine where it cannot mount skips itself and says why). Unmounted
// (lazily) when the row ends.
#include <sys/mount.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>

namespace relight::robustness {

class TmpfsMount {
 public:
  /// Makes the folder `at` and mounts a tmpfs of `size` (mount(8)'s size=, e.g. "1m") over it.
  TmpfsMount(const std::filesystem::path& at, const std::string& size) : at_(at) {
    std::filesystem::create_directories(at);
    mounted_ = ::mount("tmpfs", at.c_str(), "tmpfs", 0, ("size=" + size).c_str()) == 0;
    if (!mounted_) why_not_ = "cannot mount a " + size + " tmpfs to fill (" + std::strerror(errno) + ")";
  }
  ~TmpfsMount() {
    if (mounted_) (void)::umount2(at_.c_str(), MNT_DETACH);
  }
  TmpfsMount(const TmpfsMount&) = delete;
  TmpfsMount& operator=(const TmpfsMount&) = delete;
  [[nodiscard]] bool mounted() const { return mounted_; }
  /// Why the mount failed: the row's skip message.
  [[nodiscard]] const std::string& why_not() const { return why_not_; }

 private:
  std::filesystem::path at_;
  bool mounted_ = false;
  std::string why_not_;
};

}  // namespace relight::robustness
