// OutputFile: a file appears whole or not at all. The failing cases run in a forked
// child: one with a file-size limit (RLIMIT_FSIZE, SIGXFSZ ignored) so that writes fail
// with EFBIG as on a full disk, one killed by SIGTERM while its temporary is open.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "child_process.hpp"
#include "test_support.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/output_file.hpp"

namespace {

using vola_test::TempDir;
namespace fs = std::filesystem;

std::vector<std::string> names_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string text_of(const fs::path& path) {
  const auto bytes = vola_test::read_bytes(path);
  return {bytes.begin(), bytes.end()};
}

void put_text(const fs::path& path, const std::string& text) { vola_test::write_bytes(path, {text.begin(), text.end()}); }

// The body in a child whose files may not grow past `limit` bytes (writes then fail with
// EFBIG; SIGXFSZ ignored).
int in_child_with_file_limit(rlim_t limit, const std::function<int()>& body) {
  return vola_test::in_child([&] {
    ::signal(SIGXFSZ, SIG_IGN);
    const rlimit r{limit, limit};
    ::setrlimit(RLIMIT_FSIZE, &r);
    return body();
  });
}

TEST(OutputFile, CommitReplacesTheOldFileWholeKeepingItsPermissions) {
  TempDir dir;
  const fs::path path = dir / "out.txt";
  put_text(path, "old");
  ::chmod(path.c_str(), 0640);
  {
    vola::OutputFile out(path.string());
    out.write("new ");
    out.write("text");
    EXPECT_EQ(text_of(path), "old");  // nothing at the final name before commit()
    out.commit();
  }
  EXPECT_EQ(text_of(path), "new text");
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0640u);
  EXPECT_EQ(names_in(dir.path()), std::vector<std::string>{"out.txt"});
}

// The rename replaces whatever has the name: a link is followed, a device, FIFO or
// directory is refused (the rename would replace /dev/null itself), and so is a read-only
// file (root's rename would replace it all the same).
TEST(OutputFile, AnEmptyNameIsRefusedSayingSo) {
  try {
    vola::OutputFile out("");
    ADD_FAILURE() << "an empty name was accepted";
  } catch (const vola::IoError& e) {
    EXPECT_STREQ(e.what(), "the output file name is empty");  // it was "": `vola: ` and nothing more
  }
}

TEST(OutputFile, OnlyRegularWritableFilesAreReplacedAndLinksAreFollowed) {
  TempDir dir;
  const fs::path target = dir / "target.txt", link = dir / "link.txt";
  put_text(target, "old");
  fs::create_symlink(target, link);
  {
    vola::OutputFile out(link.string());
    out.write("through the link");
    out.commit();
  }
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(text_of(target), "through the link");

  const fs::path fifo = dir / "pipe.xyz";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  const auto refusal = [](const fs::path& p) {
    try {
      vola::OutputFile out(p.string());
    } catch (const vola::IoError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(refusal(fifo).find("pipe.xyz: is a FIFO: vola writes regular files"), std::string::npos) << refusal(fifo);
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_NE(refusal(dir.path()).find("is a directory"), std::string::npos);
  EXPECT_NE(refusal("/dev/null").find("/dev/null: is a character device"), std::string::npos);
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  const fs::path read_only = dir / "survey.las";
  put_text(read_only, "keep");
  ::chmod(read_only.c_str(), 0444);
  EXPECT_NE(refusal(read_only).find("survey.las: is read-only: vola does not replace it"), std::string::npos);
  EXPECT_EQ(text_of(read_only), "keep");
  const fs::path dangling = dir / "dangling.txt";
  fs::create_symlink(dir / "missing" / "x.txt", dangling);
  EXPECT_NE(refusal(dangling).find("symbolic link to a file that cannot be reached"), std::string::npos);
  EXPECT_EQ(names_in(dir.path()), (std::vector<std::string>{"dangling.txt", "link.txt", "pipe.xyz", "survey.las",
                                                            "target.txt"}));
}

TEST(OutputFile, AnUncommittedFileLeavesNothing) {
  TempDir dir;
  const fs::path path = dir / "out.txt";
  put_text(path, "old");
  {
    vola::OutputFile out(path.string());
    out.write("half of it");
    std::fflush(out.stream());
    // The temporary exists, unnamed, with the bytes so far.
    EXPECT_EQ(text_of(out.temporary()), "half of it");
    EXPECT_EQ(names_in(dir.path()), std::vector<std::string>{"out.txt"});
  }
  EXPECT_EQ(text_of(path), "old");
  EXPECT_EQ(names_in(dir.path()), std::vector<std::string>{"out.txt"});
}

TEST(OutputFile, AFailedWriteKeepsTheOldFileAndLeavesNoTemporary) {
  TempDir dir;
  const fs::path path = dir / "out.bin";
  put_text(path, "old");
  const int status = in_child_with_file_limit(4096, [&] {
    vola::OutputFile out(path.string());
    const std::vector<char> block(1 << 20, 'x');
    try {
      out.write(block.data(), block.size());
      out.commit();
    } catch (const vola::IoError& e) {
      return std::string(e.what()).find("File too large") != std::string::npos ? 0 : 1;
    }
    return 2;  // no error
  });
  EXPECT_EQ(status, 0);
  EXPECT_EQ(text_of(path), "old");
  EXPECT_EQ(names_in(dir.path()), std::vector<std::string>{"out.bin"});
}

TEST(OutputFile, AFailedVolWriteKeepsTheOldFile) {
  TempDir dir;
  const fs::path path = dir / "big.vol";
  put_text(path, "old");
  std::vector<vola::Voxel> voxels;
  for (std::uint32_t i = 0; i < 200000; ++i) voxels.push_back({i % 1024, (i / 1024) * 5 % 1024, i % 7});
  const vola::Tree tree = vola::build_from_voxels(voxels, 5);
  const int status = in_child_with_file_limit(8192, [&] {
    try {
      vola::write(tree, path.string());
    } catch (const vola::IoError&) {
      return 0;
    }
    return 2;
  });
  EXPECT_EQ(status, 0);
  EXPECT_EQ(text_of(path), "old");
  EXPECT_EQ(names_in(dir.path()), std::vector<std::string>{"big.vol"});
}

// A child writes `bytes` bytes to `path` (over "old") and waits; once they are written,
// it gets `signal`. Returns the names in the folder while it waited and the child's
// wait status; with `handlers` it installs remove_temporaries_on_signal() first.
struct KilledWriter {
  std::vector<std::string> names_while_writing;
  int status = 0;
};
KilledWriter kill_while_writing(const fs::path& path, std::size_t bytes, int signal, bool handlers) {
  KilledWriter result;
  int ready[2];
  if (::pipe(ready) != 0) return result;
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (handlers) vola::remove_temporaries_on_signal();
    vola::OutputFile out(path.string());
    out.write(std::string(bytes, 'x'));
    std::fflush(out.stream());
    const char one = '1';
    if (::write(ready[1], &one, 1) != 1) ::_exit(5);
    for (;;) ::pause();
  }
  char got = 0;
  if (::read(ready[0], &got, 1) == 1) result.names_while_writing = names_in(path.parent_path());
  ::kill(pid, signal);
  ::waitpid(pid, &result.status, 0);
  ::close(ready[0]);
  ::close(ready[1]);
  return result;
}

TEST(OutputFile, SigtermRemovesTheTemporaryAndEndsByTheSignal) {
  TempDir dir;
  const fs::path path = dir / "out.txt";
  put_text(path, "old");
  const KilledWriter k = kill_while_writing(path, 10, SIGTERM, true);
  EXPECT_EQ(k.names_while_writing, std::vector<std::string>{"out.txt"});  // the temporary has no name
  ASSERT_TRUE(WIFSIGNALED(k.status));
  EXPECT_EQ(WTERMSIG(k.status), SIGTERM);
  EXPECT_EQ(text_of(path), "old");
  EXPECT_EQ(names_in(dir.path()), std::vector<std::string>{"out.txt"});
}

// SIGKILL runs no handler: only a temporary without a name can leave nothing behind.
TEST(OutputFile, SigkillWhileWritingLeavesOnlyTheOldFile) {
  TempDir dir;
  const fs::path path = dir / "out.txt";
  put_text(path, "old");
  const KilledWriter k = kill_while_writing(path, std::size_t{4} << 20, SIGKILL, false);
  ASSERT_TRUE(WIFSIGNALED(k.status));
  EXPECT_EQ(WTERMSIG(k.status), SIGKILL);
  EXPECT_EQ(text_of(path), "old");
  EXPECT_EQ(names_in(dir.path()), std::vector<std::string>{"out.txt"});
}

// Libraries that open files by name (OctoMap's writers) write through temporary().
TEST(OutputFile, TheTemporaryCanBeWrittenByName) {
  TempDir dir;
  const fs::path path = dir / "out.txt";
  put_text(path, "old");
  {
    vola::OutputFile out(path.string());
    std::FILE* by_name = std::fopen(out.temporary().c_str(), "wb");
    ASSERT_NE(by_name, nullptr) << out.temporary();
    std::fputs("written by name", by_name);
    ASSERT_EQ(std::fclose(by_name), 0);
    EXPECT_EQ(text_of(path), "old");
    out.commit();
  }
  EXPECT_EQ(text_of(path), "written by name");
  EXPECT_EQ(names_in(dir.path()), std::vector<std::string>{"out.txt"});
}

}  // namespace
