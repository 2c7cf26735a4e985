#include "daemon/log_journal.h"

#include <sys/stat.h>
#include <unistd.h>

#include <charconv>
#include <cstdlib>
#include <cstring>

// The fields carry the caller's own location (Record::where), not this file's.
#define SD_JOURNAL_SUPPRESS_LOCATION
#include <systemd/sd-journal.h>

namespace atelier::log {
namespace {

// Parses a decimal number filling [begin, end) exactly.
bool parse_whole(const char* begin, const char* end, uint64_t& out) {
  if (begin == end) return false;
  auto [ptr, ec] = std::from_chars(begin, end, out);
  return ec == std::errc() && ptr == end;
}

}  // namespace

bool journal_stream_matches(const char* journal_stream, uint64_t dev, uint64_t ino) {
  if (!journal_stream) return false;
  const char* end = journal_stream + std::strlen(journal_stream);
  const char* colon = std::strchr(journal_stream, ':');
  if (!colon) return false;
  uint64_t want_dev = 0, want_ino = 0;
  if (!parse_whole(journal_stream, colon, want_dev) || !parse_whole(colon + 1, end, want_ino)) return false;
  return want_dev == dev && want_ino == ino;
}

bool stderr_is_journal() {
  const char* env = std::getenv("JOURNAL_STREAM");
  if (!env) return false;
  struct stat st;
  if (::fstat(STDERR_FILENO, &st) != 0) return false;
  return journal_stream_matches(env, static_cast<uint64_t>(st.st_dev), static_cast<uint64_t>(st.st_ino));
}

std::vector<std::string> journal_fields(const Record& record) {
  std::vector<std::string> out = {
      "MESSAGE=" + text(record),
      "PRIORITY=" + std::to_string(static_cast<int>(record.priority)),
      "SYSLOG_IDENTIFIER=atelierd",
  };
  const Fields& f = record.fields;
  if (f.job_id != 0) out.push_back("JOB_ID=" + std::to_string(f.job_id));
  if (!f.kind.empty()) out.push_back("KIND=" + f.kind);
  if (!f.device.empty()) out.push_back("DEVICE=" + f.device);
  if (!f.state.empty()) out.push_back("STATE=" + f.state);
  if (const char* file = record.where.file_name(); file && *file) {
    // Ninja compiles "../daemon/x.cc" from the build folder: the file as the tree names it.
    while (std::strncmp(file, "../", 3) == 0) file += 3;
    out.push_back(std::string("CODE_FILE=") + file);
    out.push_back("CODE_LINE=" + std::to_string(record.where.line()));
  }
  if (const char* func = record.where.function_name(); func && *func)
    out.push_back(std::string("CODE_FUNC=") + func);
  return out;
}

JournalSend sd_journal_sender() {
  return [](const struct iovec* fields, int count) { return sd_journal_sendv(fields, count); };
}

void JournalSink::write(const Record& record) {
  const std::vector<std::string> fields = journal_fields(record);
  std::vector<struct iovec> iov;
  iov.reserve(fields.size());
  for (const std::string& field : fields)
    iov.push_back({const_cast<char*>(field.data()), field.size()});
  if (send_(iov.data(), static_cast<int>(iov.size())) < 0) fallback_.write(record);
}

}  // namespace atelier::log
