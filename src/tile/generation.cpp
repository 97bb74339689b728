#include "generation.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <set>
#include <span>

#include "vola/error.hpp"
#include "vola/tile/tile_index.hpp"

namespace vola::tile::detail {

namespace fs = std::filesystem;

namespace {

constexpr std::string_view kPrefix = ".generation-";

// The number of a ".generation-<n>" name (or of a path starting with one), else 0.
unsigned long generation_number(std::string_view name) {
  if (name.substr(0, kPrefix.size()) != kPrefix) return 0;
  name.remove_prefix(kPrefix.size());
  unsigned long n = 0;
  std::size_t digits = 0;
  for (; digits < name.size() && name[digits] >= '0' && name[digits] <= '9' && digits < 9; ++digits)
    n = 10 * n + static_cast<unsigned long>(name[digits] - '0');
  const bool ends = digits == name.size() || name[digits] == '/';
  return digits > 0 && ends ? n : 0;
}

std::string host_name() {
  char host[HOST_NAME_MAX + 1] = {};
  if (::gethostname(host, sizeof host - 1) != 0 || host[0] == '\0') return "host";
  std::string out(host);
  for (char& c : out)
    if (c == '-' || c == '/') c = '_';  // '-' separates the name's fields
  return out;
}

}  // namespace

OutputLock::OutputLock(const fs::path& output_dir, Communicator& comm) {
  std::uint8_t held = 0;  // rank 0: 1 when another process holds the folder
  if (comm.rank() == 0) {
    fd_ = ::open((output_dir / ".lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ >= 0 && ::flock(fd_, LOCK_EX | LOCK_NB) != 0) held = errno == EWOULDBLOCK ? 1 : 0;
  }
  const auto answers = comm.all_gather(std::span<const std::uint8_t>(&held, comm.rank() == 0 ? 1 : 0));
  if (!answers.empty() && !answers[0].empty() && answers[0][0] == 1) {
    if (fd_ >= 0) ::close(fd_);
    throw IoError(output_dir.string() + ": another vola tile is writing this tile set (it holds " +
                  (output_dir / ".lock").string() + "); wait for it to end, or give another folder");
  }
}

OutputLock::~OutputLock() {
  if (fd_ >= 0) ::close(fd_);  // the lock goes with the descriptor
}

Generation begin_generation(const fs::path& output_dir, Communicator& comm) {
  Generation g;
  g.output_dir = output_dir;
  unsigned long live = 0;
  const fs::path index_path = output_dir / kIndexFileName;
  std::error_code ec;
  if (fs::is_regular_file(index_path, ec)) {
    try {
      const TileIndexFile index = read_tile_index(index_path.string());
      for (const TileEntry& t : index.tiles) g.previous_files.push_back(t.file);
      for (const OverviewEntry& o : index.overviews) g.previous_files.push_back(o.file);
      if (!index.tiles.empty()) live = generation_number(index.tiles.front().file);
    } catch (const Error&) {
      // Unreadable: no live set to keep; its files are replaced or left as they are.
    }
  }
  if (live > 0) g.previous_name = std::string(kPrefix) + std::to_string(live);
  g.name = std::string(kPrefix) + std::to_string(live + 1);
  if (comm.rank() == 0) {
    std::vector<fs::path> stale;  // listed first: removing while iterating may skip entries
    for (const auto& entry : fs::directory_iterator(output_dir, ec)) {
      const std::string name = entry.path().filename().string();
      if (generation_number(name) > 0 && name != g.previous_name) stale.push_back(entry.path());
    }
    for (const fs::path& p : stale) fs::remove_all(p, ec);
  }
  comm.barrier();
  fs::create_directories(g.dir());
  return g;
}

void retire_previous(const Generation& current) {
  std::error_code ec;
  if (!current.previous_name.empty() && current.previous_name != current.name) {
    fs::remove_all(current.output_dir / current.previous_name, ec);
    return;
  }
  // The older layout: tiles straight in OUTDIR, overviews in OUTDIR/overviews/L<n>. Only
  // the files its index named go, then the folders they leave empty (fs::remove keeps a
  // folder that is not): the user's own files there stay.
  std::set<fs::path> folders;
  for (const std::string& file : current.previous_files) {
    if (generation_number(file) != 0) continue;
    fs::remove(current.output_dir / file, ec);
    for (fs::path up = fs::path(file).parent_path(); !up.empty(); up = up.parent_path()) folders.insert(up);
  }
  for (auto folder = folders.rbegin(); folder != folders.rend(); ++folder)  // deeper ones first
    fs::remove(current.output_dir / *folder, ec);
}

std::string spill_folder_name(int rank) {
  return "rank-" + std::to_string(rank) + "-" + host_name() + "-" + std::to_string(::getpid());
}

void remove_stale_spill(const fs::path& spill_root) {
  const std::string mine = std::string("-").append(host_name()).append("-");
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(spill_root, ec)) {
    const std::string name = entry.path().filename().string();
    const auto at = name.rfind(mine);
    if (name.rfind("rank-", 0) != 0 || at == std::string::npos) continue;  // another host's, or not ours
    const std::string pid_text = name.substr(at + mine.size());
    char* end = nullptr;
    const long pid = std::strtol(pid_text.c_str(), &end, 10);
    if (pid_text.empty() || *end != '\0' || pid <= 0) continue;
    // Gone (ESRCH): its run was killed. Alive, or not ours to ask (EPERM): kept.
    if (::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) fs::remove_all(entry.path(), ec);
  }
}

}  // namespace vola::tile::detail
