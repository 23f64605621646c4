#include "relight/core/atomic_file.h"

#include <gtest/gtest.h>

#include "relight/core/error.h"
#include "temp_dir.h"

namespace relight {
namespace {

TEST(AtomicFile, WritesAndReplacesWithoutLeavingTemporaries) {
  test::TempDir dir;
  const auto path = dir.path() / "out.txt";
  write_file_atomically(path, std::string_view("first"));
  write_file_atomically(path, std::string_view("second"));
  EXPECT_EQ(read_text_file(path), "second");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
}

TEST(AtomicFile, FailureNamesThePathAndLeavesNothing) {
  test::TempDir dir;
  const auto path = dir.path() / "missing-folder" / "out.txt";
  try {
    write_file_atomically(path, std::string_view("x"));
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_THROW(read_text_file(path), Error);
}

}  // namespace
}  // namespace relight
