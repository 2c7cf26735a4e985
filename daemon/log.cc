#include "daemon/log.h"

#include <unistd.h>

#include <atomic>

#include "daemon/log_journal.h"

namespace atelier::log {
namespace {

std::atomic<bool> g_verbose{false};
std::atomic<Sink*> g_sink{nullptr};

StderrSink& plain_stderr() {
  static StderrSink sink(STDERR_FILENO);
  return sink;
}

}  // namespace

std::string text(const Record& record) {
  const Fields& f = record.fields;
  std::string prefix;
  if (f.job_id != 0) {
    prefix = "job " + std::to_string(f.job_id);
    std::string about = f.kind;
    if (!f.device.empty()) about += (about.empty() ? "" : ", ") + f.device;
    if (!about.empty()) prefix += " (" + about + ")";
  } else if (!f.device.empty()) {
    prefix = "device " + f.device;
  }
  return prefix.empty() ? record.message : prefix + ": " + record.message;
}

std::string StderrSink::line(const Record& record) const {
  std::string out;
  if (prefixes_) {
    out = "<" + std::to_string(static_cast<int>(record.priority)) + ">";
  } else if (record.priority == Priority::error) {
    out = "error: ";
  } else if (record.priority == Priority::warning) {
    out = "warning: ";
  }
  return out + text(record) + "\n";
}

void StderrSink::write(const Record& record) {
  const std::string l = line(record);
  // One write so that lines from different threads never interleave.
  ssize_t ignored = ::write(fd_, l.data(), l.size());
  (void)ignored;
}

void set_sink(Sink* sink) { g_sink = sink; }

ScopedSink::ScopedSink(Sink& sink) : previous_(g_sink.exchange(&sink)) {}
ScopedSink::~ScopedSink() { g_sink = previous_; }

void init() {
  if (!stderr_is_journal()) return;  // plain lines, the default
  // Entries the journal refuses (it is restarting, the entry is too large) still reach it,
  // as lines on the stderr stream it reads, with their priority.
  static StderrSink fallback(STDERR_FILENO, true);
  static JournalSink journal(sd_journal_sender(), fallback);
  set_sink(&journal);
}

void write(Priority priority, const std::string& message, const Fields& fields, std::source_location where) {
  if (priority == Priority::debug && !g_verbose) return;
  Sink* sink = g_sink.load();
  (sink ? *sink : plain_stderr()).write(Record{priority, message, fields, where});
}

void set_verbose(bool on) { g_verbose = on; }

}  // namespace atelier::log
