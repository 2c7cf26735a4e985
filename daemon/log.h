// atelierd's log: each record is a priority, a message and the job it is about (job id, kind,
// device, state: log::Fields), so that the journal can show one job's story
// (`journalctl -u atelierd JOB_ID=12`). Where a record goes is a Sink:
//   - under systemd, with stderr connected to the journal (daemon/log_journal.h), a native
//     journal entry with the fields as JOB_ID=, KIND=, DEVICE=, STATE= (sd_journal_sendv);
//   - otherwise one plain line on stderr, the fields shown compactly in front of the message:
//     "job 12 (knit, knitter): completed: knitted 200 rows on knitter".
// init() picks the sink; until then (and in tests, which install their own sink with
// ScopedSink) records go to stderr as plain lines.
//
// Threading: every function is thread-safe. A sink gets whole records, and the stderr sink
// writes each one with one write(2), so lines from different threads never interleave.
// Ownership: set_sink() borrows the sink, which must outlive its use (ScopedSink restores
// the previous one when it goes out of scope).
#pragma once

#include <cstdint>
#include <source_location>
#include <string>

namespace atelier::log {

// syslog(3) levels, which are also the journal's PRIORITY= values.
enum class Priority { error = 3, warning = 4, info = 6, debug = 7 };

// What a record is about. Empty members (job_id 0) are left out of the record.
struct Fields {
  int64_t job_id = 0;  // the job's id in the store; 0 when the record is about no job
  std::string kind;    // the job's kind, e.g. "knit"
  std::string device;  // the [[device]] name involved, e.g. "knitter"
  std::string state;   // only on a state change: the state the job entered, e.g. "running"
};

// The fields of a record about a device alone ("device laser: offline").
inline Fields device_fields(const std::string& device) {
  Fields f;
  f.device = device;
  return f;
}

struct Record {
  Priority priority = Priority::info;
  std::string message;  // without the job or device prefix: text() adds it
  Fields fields;
  std::source_location where;  // the call site (the journal's CODE_FILE=, CODE_LINE=, CODE_FUNC=)
};

// The record as one line of text, without a newline: "job 12 (knit, knitter): MESSAGE" for a
// job (kind and device when known), "device knitter: MESSAGE" for a device alone, the message
// alone otherwise. Both the journal's MESSAGE= and the plain stderr line are this text.
std::string text(const Record& record);

class Sink {
 public:
  virtual ~Sink() = default;
  // Called from any thread, possibly at once from several.
  virtual void write(const Record& record) = 0;
};

// One line per record on `fd` (normally stderr), written with one write(2).
// `priority_prefixes`: start each line with "<N>" (N = PRIORITY), as journald reads stdout
// and stderr streams; for a stderr connected to the journal, where a native entry could not be
// sent. Otherwise error and warning lines start with "error: " and "warning: ".
class StderrSink : public Sink {
 public:
  explicit StderrSink(int fd, bool priority_prefixes = false) : fd_(fd), prefixes_(priority_prefixes) {}
  void write(const Record& record) override;
  // The line write() writes, newline included.
  std::string line(const Record& record) const;

 private:
  int fd_;
  bool prefixes_;
};

// Where records go from now on (nullptr: back to plain stderr lines).
void set_sink(Sink* sink);

// Installs `sink` for its scope, for tests that look at the records themselves.
class ScopedSink {
 public:
  explicit ScopedSink(Sink& sink);
  ~ScopedSink();
  ScopedSink(const ScopedSink&) = delete;
  ScopedSink& operator=(const ScopedSink&) = delete;

 private:
  Sink* previous_;
};

// Chooses the sink for the daemon's life: the journal when stderr is the journal's stream
// (log_journal.h: JOURNAL_STREAM), plain stderr lines otherwise. Call once, early in main().
void init();

void write(Priority priority, const std::string& message, const Fields& fields = {},
           std::source_location where = std::source_location::current());
inline void error(const std::string& message, const Fields& fields = {},
                  std::source_location where = std::source_location::current()) {
  write(Priority::error, message, fields, where);
}
inline void warning(const std::string& message, const Fields& fields = {},
                    std::source_location where = std::source_location::current()) {
  write(Priority::warning, message, fields, where);
}
inline void info(const std::string& message, const Fields& fields = {},
                 std::source_location where = std::source_location::current()) {
  write(Priority::info, message, fields, where);
}
inline void debug(const std::string& message, const Fields& fields = {},
                  std::source_location where = std::source_location::current()) {
  write(Priority::debug, message, fields, where);
}
// Debug records are dropped unless enabled (atelierd --verbose).
void set_verbose(bool on);

}  // namespace atelier::log
