// Watches <spool>/incoming for complete files: inotify (close-after-write, moved-into, and
// on creation: symlinks, folders, FIFOs, sockets and hard links, which never get a
// close-after-write) or polling for network shares (complete = size and mtime
// unchanged for settle_ms). Reports candidates; it never moves anything (claiming is the
// JobService's job).
//
// Time: the poll-mode settle timer reads the Clock given (real_clock() in the daemon; a test
// moves a FakeClock between collect() calls).
// Threading: used from one thread (the daemon's main loop). Owns its inotify descriptor and
// borrows the clock, which must outlive it.
#pragma once

#include <chrono>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "base/clock.h"
#include "daemon/config.h"
#include "daemon/spool_layout.h"

namespace atelier {

class HotFolder {
 public:
  HotFolder(SpoolLayout layout, WatchMode mode, int settle_ms, Clock& clock = real_clock());
  ~HotFolder();
  HotFolder(const HotFolder&) = delete;
  HotFolder& operator=(const HotFolder&) = delete;

  // Every entry now in incoming/ and its subfolders that is not temporary and not a
  // companion (sidecar, relax mask): used at startup and after a watch overflow.
  std::vector<std::filesystem::path> scan() const;

  // A descriptor that becomes readable when wait() has something (inotify), or -1 in poll
  // mode (the caller then calls collect() every poll_interval()).
  int fd() const { return inotify_fd_; }
  std::chrono::milliseconds poll_interval() const;

  // Returns the candidates that became complete since the last call. Non-blocking.
  std::vector<std::filesystem::path> collect();

 private:
  void add_watch(const std::filesystem::path& dir);
  std::vector<std::filesystem::path> collect_inotify();
  std::vector<std::filesystem::path> collect_poll();

  SpoolLayout layout_;
  WatchMode mode_;
  int settle_ms_;
  Clock& clock_;
  int inotify_fd_ = -1;
  std::map<int, std::filesystem::path> watches_;  // inotify watch descriptor -> folder
  struct Seen {
    uintmax_t size;
    std::filesystem::file_time_type mtime;
    Clock::time_point since;  // on clock_
    bool reported;
  };
  std::map<std::filesystem::path, Seen> polled_;
};

}  // namespace atelier
