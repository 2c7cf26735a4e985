// A pseudo-terminal whose slave is published under a stable path (a symlink), as a USB serial
// adapter appears under /dev/serial/by-id. Linux only (openpty from <pty.h>, TIOCGPTPEER).
// Shared by the machine emulators (atelier-knit-emu, atelier-laser-emu).
//
// The host's open and close are the board's DTR line: the emulator keeps no slave descriptor of
// its own, so once every host descriptor is closed (a close, or the kernel's when the host is
// killed) the master sees POLLHUP (reads fail with EIO) until a host opens the slave again.
// host_connected() tells which it is; an event loop polls the master only while a host is
// connected (a hung-up master polls ready at once, forever) and otherwise looks again every few
// milliseconds. After a hang-up, after_hangup() clears what a dead host left on the slave: bytes
// it never read (a real port's driver flushes them on close) and its exclusive lock (TIOCEXCL
// outlives a killed holder on a pty, so the next non-root host would get EBUSY). Where the
// emulator may not open the slave to do that, the pty is replaced by a fresh one at the same
// link path (master_fd() and slave_name() change).
//
// Ownership: a PtyLink owns the master fd and the symlink; close() (or the destructor) closes the
// master and removes the symlink. Threading: one thread.
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

  // True while some host has the slave open (the master does not report POLLHUP). Does not block.
  bool host_connected() const;
  // After the last host closed the slave: discards the bytes it left unread and its exclusive
  // lock (or replaces the pty, see above). Throws std::runtime_error if a replacement fails.
  void after_hangup();

  // Waits (at least 50 ms, then in 2 ms steps, at most `max_ms`) until the host has read everything written
  // to the master; closing the master discards unread bytes. Returns false on timeout. Where the
  // slave cannot be looked at (held exclusively, and we are not root), only the 50 ms pass.
  bool drain(int max_ms);

  // Unplugs: closes the pty and removes the symlink if it still points at our slave.
  void close();

 private:
  void open_pty();             // a fresh master and raw slave; sets master_ and slave_name_
  int open_slave() const;      // a descriptor on our slave (TIOCGPTPEER), or -1 with errno

  std::string link_;
  std::string slave_name_;
  int master_ = -1;
};

}  // namespace atelier::emu
