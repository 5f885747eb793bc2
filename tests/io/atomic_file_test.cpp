#include "io/atomic_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>

#include "core/error.h"
#include "core/interrupt.h"
#include "io_test_support.h"

namespace glint::io {
namespace {

using test::error_of;
using test::read_text;
using test::scratch;
using test::write_text;

// The files in `folder`, by name.
std::vector<std::string> files_in(const std::filesystem::path& folder) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

TEST(AtomicFile, UncommittedWritesLeaveNoFileAndTheOldTargetUntouched) {
  const std::string fresh = scratch("fresh.txt");
  {
    AtomicFile file(fresh, false);
    file.stream() << "abandoned";
  }
  EXPECT_TRUE(files_in(test::scratch_folder()).empty());

  const std::string path = scratch("atomic.txt");
  write_text(path, "old");
  {
    AtomicFile file(path, false);
    file.stream() << "new but abandoned";
    EXPECT_EQ(files_in(test::scratch_folder()).size(), 2u);  // the target and the temporary
    EXPECT_EQ(read_text(path), "old");
  }
  EXPECT_EQ(read_text(path), "old");
  EXPECT_EQ(files_in(test::scratch_folder()), std::vector<std::string>{"atomic.txt"});
}

TEST(AtomicFile, CommitReplacesTheTargetAndLeavesNoTemporary) {
  const std::string path = scratch("atomic.bin");
  write_text(path, "old");
  {
    AtomicFile file(path);
    file.stream() << "new\n";
    file.commit();
  }
  EXPECT_EQ(read_text(path), "new\n");
  EXPECT_EQ(files_in(test::scratch_folder()), std::vector<std::string>{"atomic.bin"});
}

// A job interrupted by SIGINT however late leaves no output: the commit itself checks.
TEST(AtomicFile, CommitAfterAnInterruptLeavesNothing) {
  const std::filesystem::path folder = test::scratch_folder() / "interrupted";
  std::filesystem::create_directories(folder);
  {
    AtomicFile file((folder / "out.txt").string());
    file.stream() << "finished";
    set_interrupt_signal_for_testing(SIGINT);
    EXPECT_THROW(file.commit(), Interrupted);
    set_interrupt_signal_for_testing(0);
  }
  EXPECT_TRUE(files_in(folder).empty());
}

TEST(AtomicFile, CreatesMissingFolders) {
  const std::string path = scratch("missing/deeper/out.txt");
  {
    AtomicFile file(path, false);
    file.stream() << "data";
    file.commit();
  }
  EXPECT_EQ(read_text(path), "data");
}

TEST(AtomicFile, AFileWhereAFolderShouldBeIsAnError) {
  write_text(scratch("plain"), "a file");
  const std::string path = scratch("plain/out.ply");
  const Error e = error_of([&] { AtomicFile file(path); });
  EXPECT_EQ(e.file(), path);
  EXPECT_EQ(e.element(), "");
  EXPECT_THAT(e.reason(), ::testing::HasSubstr("cannot create its folder"));
}

TEST(AtomicFile, FailedRenameIsAnErrorAndRemovesTheTemporary) {
  const std::string path = scratch("occupied");
  std::filesystem::create_directories(std::filesystem::path(path) / "child");
  AtomicFile file(path);
  file.stream() << "data";
  EXPECT_THAT(error_of([&] { file.commit(); }).reason(),
              ::testing::HasSubstr("cannot move the finished file into place"));
  EXPECT_EQ(files_in(test::scratch_folder()), std::vector<std::string>{"occupied"});
}

}  // namespace
}  // namespace glint::io
