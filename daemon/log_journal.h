// The journal side of daemon/log.h: whether stderr is connected to journald, the fields of a
// native journal entry, and the sink that sends them (sd_journal_sendv from libsystemd).
//
// A record becomes these fields (empty ones left out):
//   MESSAGE=<log::text(record)>  PRIORITY=<3|4|6|7>  SYSLOG_IDENTIFIER=atelierd
//   JOB_ID=<id>  KIND=<kind>  DEVICE=<device>  STATE=<state entered>
//   CODE_FILE=<source file, e.g. daemon/job_log.cc>  CODE_LINE=<line>  CODE_FUNC=<function>
// so `journalctl -u atelierd JOB_ID=12` lists one job's records, and
// `journalctl -u atelierd STATE=failed` every failure.
//
// Threading: everything here may be called from any thread (sd_journal_sendv is thread-safe).
#pragma once

#include <sys/uio.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "daemon/log.h"

namespace atelier::log {

// True when `journal_stream` (the JOURNAL_STREAM environment variable systemd sets for a
// service whose stdout or stderr is the journal: "DEVICE:INODE" in decimal) names the file
// whose st_dev and st_ino are given, as sd-daemon(3) says to check. False for nullptr or a
// malformed value.
bool journal_stream_matches(const char* journal_stream, uint64_t dev, uint64_t ino);

// journal_stream_matches() for getenv("JOURNAL_STREAM") and fstat() of stderr.
bool stderr_is_journal();

// The journal entry for `record`, one "NAME=value" string per field (see the top).
std::vector<std::string> journal_fields(const Record& record);

// Sends one entry of `count` fields; 0 on success, a negative errno on failure
// (the signature of sd_journal_sendv()).
using JournalSend = std::function<int(const struct iovec* fields, int count)>;
// sd_journal_sendv(), which writes to /run/systemd/journal/socket.
JournalSend sd_journal_sender();

// Sends each record as a native journal entry through `send`; a record the journal refuses
// goes to `fallback` instead, so that nothing is lost. Borrows `fallback`.
class JournalSink : public Sink {
 public:
  JournalSink(JournalSend send, Sink& fallback) : send_(std::move(send)), fallback_(fallback) {}
  void write(const Record& record) override;

 private:
  JournalSend send_;
  Sink& fallback_;
};

}  // namespace atelier::log
