// A pseudo-terminal whose slave is published under a stable path (a symlink), as a USB serial
// adapter appears under /dev/serial/by-id. Linux only (openpty from <pty.h>). Shared by the
// machine emulators (atelier-knit-emu, atelier-laser-emu).
//
// Ownership: a PtyLink owns the master fd, one slave fd and the symlink; close() (or the
// destructor) closes both fds and removes the symlink. Keeping a slave fd open ourselves means
// the master never sees EIO/HUP while no host has the port open.
// Threading: one thread.
#pragma once

#include <string>

namespace atelier::emu {

class PtyLink {
 public:
  // Opens a pty, puts the slave in raw mode, and symlinks its name at `link_path`, replacing
  // an existing symlink. Throws std::runtime_error naming the path and the problem (e.g. when
  // `link_path` is a regular file, which it refuses to overwrite).
  explicit PtyLink(const std::string& link_path);
  ~PtyLink();
  PtyLink(const PtyLink&) = delete;
  PtyLink& operator=(const PtyLink&) = delete;

  int master_fd() const { return master_; }            // non-blocking
  const std::string& slave_name() const { return slave_name_; }  // e.g. /dev/pts/7
  const std::string& link_path() const { return link_; }

  // Waits (at least 50 ms, then in 2 ms steps, at most `max_ms`) until the host has read everything written
  // to the master; closing the master discards unread bytes. Returns false on timeout.
  bool drain(int max_ms);

  // Unplugs: closes the pty and removes the symlink if it still points at our slave.
  void close();

 private:
  std::string link_;
  std::string slave_name_;
  int master_ = -1;
  int slave_ = -1;
};

}  // namespace atelier::emu
