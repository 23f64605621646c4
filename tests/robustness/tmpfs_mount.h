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
  TmpfsMount(const std::filesystem::path& at, const char* options) : at_(at) {
    mounted_ = ::mount("tmpfs", at.c_str(), "tmpfs", 0, options) == 0;
    if (!mounted_) why_not_ = std::strerror(errno);
  }
  ~TmpfsMount() {
    if (mounted_) (void)::umount2(at_.c_str(), MNT_DETACH);
  }
  TmpfsMount(const TmpfsMount&) = delete;
  TmpfsMount& operator=(const TmpfsMount&) = delete;
  [[nodiscard]] bool mounted() const { return mounted_; }
  [[nodiscard]] const std::string& why_not() const { return why_not_; }

 private:
  std::filesystem::path at_;
  bool mounted_ = false;
  std::string why_not_;
};

}  // namespace relight::robustness
