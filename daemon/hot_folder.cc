#include "daemon/hot_folder.h"

#include <sys/inotify.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "base/error.h"
#include "convert/convert.h"
#include "convert/kinds.h"
#include "daemon/log.h"

namespace fs = std::filesystem;

namespace atelier {
namespace {

// A job file (NAME.toml directly in incoming/, or in the folder of a kind that converts job
// files) is a job even with dots in its name: it is nobody's sidecar.
bool is_job_file(const SpoolLayout& layout, const fs::path& path) {
  if (path.extension() != ".toml") return false;
  const fs::path parent = path.parent_path();
  return parent == layout.incoming() || converts_job_file(parent.filename().string());
}

bool is_candidate(const SpoolLayout& layout, const fs::path& path) {
  const std::string name = path.filename().string();
  return !is_temporary_name(name) && (!companion_of(name) || is_job_file(layout, path));
}

constexpr uint32_t kDirMask = IN_CLOSE_WRITE | IN_MOVED_TO | IN_CREATE | IN_DELETE_SELF;

}  // namespace

HotFolder::HotFolder(SpoolLayout layout, WatchMode mode, int settle_ms, Clock& clock)
    : layout_(std::move(layout)), mode_(mode), settle_ms_(settle_ms), clock_(clock) {
  if (mode_ != WatchMode::inotify) return;
  inotify_fd_ = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  if (inotify_fd_ < 0) throw InternalError(std::string("inotify_init1: ") + strerror(errno));
  add_watch(layout_.incoming());
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(layout_.incoming(), ec))
    if (entry.is_directory() && !entry.is_symlink()) add_watch(entry.path());
}

HotFolder::~HotFolder() {
  if (inotify_fd_ >= 0) ::close(inotify_fd_);
}

void HotFolder::add_watch(const fs::path& dir) {
  int wd = inotify_add_watch(inotify_fd_, dir.c_str(), kDirMask | IN_ONLYDIR | IN_DONT_FOLLOW);
  if (wd < 0) {
    log::warning(dir.string() + ": cannot watch: " + strerror(errno));
    return;
  }
  watches_[wd] = dir;
}

std::chrono::milliseconds HotFolder::poll_interval() const {
  return std::chrono::milliseconds(std::max(50, settle_ms_ / 4));
}

std::vector<fs::path> HotFolder::scan() const {
  std::vector<fs::path> out;
  std::error_code ec;
  for (const auto& top : fs::directory_iterator(layout_.incoming(), ec)) {
    if (!is_candidate(layout_, top.path())) continue;
    if (top.is_directory() && !top.is_symlink()) {
      std::error_code ec2;
      for (const auto& entry : fs::directory_iterator(top.path(), ec2))
        if (is_candidate(layout_, entry.path())) out.push_back(entry.path());
    } else {
      out.push_back(top.path());
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<fs::path> HotFolder::collect() {
  return mode_ == WatchMode::inotify ? collect_inotify() : collect_poll();
}

std::vector<fs::path> HotFolder::collect_inotify() {
  std::vector<fs::path> out;
  alignas(struct inotify_event) char buf[16384];
  bool rescan = false;
  for (;;) {
    ssize_t n = ::read(inotify_fd_, buf, sizeof buf);
    if (n <= 0) break;
    for (char* p = buf; p < buf + n;) {
      auto* ev = reinterpret_cast<struct inotify_event*>(p);
      p += sizeof(struct inotify_event) + ev->len;
      if (ev->mask & IN_Q_OVERFLOW) {
        rescan = true;
        continue;
      }
      auto it = watches_.find(ev->wd);
      if (it == watches_.end()) continue;
      if (ev->mask & (IN_IGNORED | IN_DELETE_SELF)) {
        watches_.erase(it);
        continue;
      }
      if (ev->len == 0) continue;
      std::string name = ev->name;
      fs::path path = it->second / name;
      const bool at_top = it->second == layout_.incoming();
      const bool is_dir = ev->mask & IN_ISDIR;
      if (at_top && is_dir && (ev->mask & (IN_CREATE | IN_MOVED_TO))) {
        // A new kind folder: watch it, and pick up whatever landed before the watch existed.
        add_watch(path);
        std::error_code ec;
        for (const auto& entry : fs::directory_iterator(path, ec))
          if (is_candidate(layout_, entry.path())) out.push_back(entry.path());
        continue;
      }
      if (!is_candidate(layout_, path)) continue;
      if (ev->mask & (IN_CLOSE_WRITE | IN_MOVED_TO)) {
        out.push_back(path);
      } else if (ev->mask & IN_CREATE) {
        // Entries that never get a close-after-write are reported when they appear: symlinks,
        // folders, FIFOs, sockets (the claim fails each with a reason), and hard links (a
        // regular file with more than one link arrived complete: link(2) writes nothing). A
        // regular file with one link is being written by whoever created it: its
        // close-after-write reports it.
        struct stat st;
        if (::lstat(path.c_str(), &st) == 0 && (!S_ISREG(st.st_mode) || st.st_nlink > 1))
          out.push_back(path);
      }
    }
  }
  if (rescan) {
    log::warning("hot folder: inotify queue overflowed; scanning " + layout_.incoming().string());
    auto all = scan();
    out.insert(out.end(), all.begin(), all.end());
  }
  return out;
}

std::vector<fs::path> HotFolder::collect_poll() {
  std::vector<fs::path> out;
  auto now = clock_.now();
  std::map<fs::path, Seen> next;
  for (const auto& path : scan()) {
    std::error_code ec;
    auto st = fs::symlink_status(path, ec);
    if (ec) continue;
    uintmax_t size = fs::is_regular_file(st) ? fs::file_size(path, ec) : 0;
    auto mtime = fs::is_symlink(st) ? fs::file_time_type{} : fs::last_write_time(path, ec);
    Seen seen{size, mtime, now, false};
    if (auto it = polled_.find(path); it != polled_.end()) {
      if (it->second.size == size && it->second.mtime == mtime) seen = it->second;
    }
    if (!seen.reported &&
        now - seen.since >= std::chrono::milliseconds(settle_ms_)) {
      seen.reported = true;
      out.push_back(path);
    }
    next[path] = seen;
  }
  polled_ = std::move(next);
  return out;
}

}  // namespace atelier
