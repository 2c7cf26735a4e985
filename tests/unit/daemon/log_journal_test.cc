// The journal side of the log, without a journal (this machine has no journald; the boot test
// reads a real one): stderr counts as the journal only when JOURNAL_STREAM names its device
// and inode, as sd-daemon(3) says; a record becomes a native entry with JOB_ID, KIND, DEVICE
// and STATE beside MESSAGE, PRIORITY and SYSLOG_IDENTIFIER; and an entry the journal refuses
// still reaches stderr.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fcntl.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <optional>
#include <string>
#include <vector>

#include "daemon/log_journal.h"
#include "tests/e2e/daemon_harness.h"
#include "tests/support/log_capture.h"

namespace atelier::log {
namespace {

using ::testing::Contains;
using ::testing::ElementsAre;
using ::testing::Not;
using ::testing::StartsWith;

TEST(JournalStream, MatchesOnlyTheDeviceAndInodeItNames) {
  EXPECT_TRUE(journal_stream_matches("8:123456", 8, 123456));
  EXPECT_FALSE(journal_stream_matches("8:123456", 8, 123457));
  EXPECT_FALSE(journal_stream_matches("9:123456", 8, 123456));
  for (const char* bad : {"", "8", "8:", ":123456", "8:123456x", "x8:123456", "8:-1", "8:12:34", " 8:123456"})
    EXPECT_FALSE(journal_stream_matches(bad, 8, 123456)) << "'" << bad << "'";
  EXPECT_FALSE(journal_stream_matches(nullptr, 8, 123456));
}

// Points stderr at a file for its scope and sets JOURNAL_STREAM as given (unset for nullopt),
// restoring both afterwards.
class StderrAndEnvironment {
 public:
  StderrAndEnvironment(const std::string& file, const std::function<std::optional<std::string>(const struct stat&)>& env) {
    saved_fd_ = ::dup(STDERR_FILENO);
    if (const char* old = ::getenv("JOURNAL_STREAM")) saved_env_ = old;
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0600);
    ::dup2(fd, STDERR_FILENO);
    struct stat st;
    ::fstat(fd, &st);
    ::close(fd);
    if (auto value = env(st)) {
      ::setenv("JOURNAL_STREAM", value->c_str(), 1);
    } else {
      ::unsetenv("JOURNAL_STREAM");
    }
  }
  ~StderrAndEnvironment() {
    ::dup2(saved_fd_, STDERR_FILENO);
    ::close(saved_fd_);
    if (saved_env_) {
      ::setenv("JOURNAL_STREAM", saved_env_->c_str(), 1);
    } else {
      ::unsetenv("JOURNAL_STREAM");
    }
  }

 private:
  int saved_fd_ = -1;
  std::optional<std::string> saved_env_;
};

std::string stream_of(const struct stat& st) {
  return std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
}

TEST(JournalStream, StderrIsTheJournalWhenJournalStreamNamesIt) {
  test::TempDir tmp;
  {
    StderrAndEnvironment stderr_is(tmp.path() / "stream", [](const struct stat& st) { return stream_of(st); });
    EXPECT_TRUE(stderr_is_journal());
  }
  {
    // systemd set it for stdout, or a child inherited it and was started with another stderr.
    StderrAndEnvironment stderr_is(tmp.path() / "other", [&](const struct stat&) {
      struct stat elsewhere;
      ::stat(tmp.path().c_str(), &elsewhere);
      return std::optional(stream_of(elsewhere));
    });
    EXPECT_FALSE(stderr_is_journal());
  }
  {
    StderrAndEnvironment stderr_is(tmp.path() / "plain", [](const struct stat&) { return std::nullopt; });
    EXPECT_FALSE(stderr_is_journal());
  }
}

Record job_record() {
  return Record{Priority::warning, "failed: knitter: the pattern is 230 stitches wide", {12, "knit", "knitter", "failed"},
                std::source_location::current()};
}

TEST(JournalEntry, CarriesTheJobFieldsBesideMessagePriorityAndIdentifier) {
  const std::vector<std::string> fields = journal_fields(job_record());
  EXPECT_THAT(fields, Contains("MESSAGE=job 12 (knit, knitter): failed: knitter: the pattern is 230 stitches wide"));
  EXPECT_THAT(fields, Contains("PRIORITY=4"));
  EXPECT_THAT(fields, Contains("SYSLOG_IDENTIFIER=atelierd"));
  EXPECT_THAT(fields, Contains("JOB_ID=12"));
  EXPECT_THAT(fields, Contains("KIND=knit"));
  EXPECT_THAT(fields, Contains("DEVICE=knitter"));
  EXPECT_THAT(fields, Contains("STATE=failed"));
  EXPECT_THAT(fields, Contains(StartsWith("CODE_FILE=")));
  EXPECT_THAT(fields, Contains(StartsWith("CODE_LINE=")));
}

TEST(JournalEntry, LeavesOutFieldsTheRecordDoesNotHave) {
  const std::vector<std::string> fields =
      journal_fields(Record{Priority::info, "atelierd ready", {}, std::source_location::current()});
  EXPECT_THAT(fields, Contains("MESSAGE=atelierd ready"));
  EXPECT_THAT(fields, Contains("PRIORITY=6"));
  for (const char* name : {"JOB_ID=", "KIND=", "DEVICE=", "STATE="})
    EXPECT_THAT(fields, Not(Contains(StartsWith(name))));
}

TEST(JournalSinkSend, SendsOneEntryWithEveryField) {
  std::vector<std::vector<std::string>> sent;
  test::LogCapture fallback;
  JournalSink sink(
      [&](const struct iovec* iov, int n) {
        std::vector<std::string> entry;
        for (int i = 0; i < n; ++i) entry.emplace_back(static_cast<const char*>(iov[i].iov_base), iov[i].iov_len);
        sent.push_back(entry);
        return 0;
      },
      fallback);
  sink.write(job_record());
  ASSERT_EQ(sent.size(), 1u);
  EXPECT_EQ(sent[0], journal_fields(job_record()));
  EXPECT_TRUE(fallback.records().empty());
}

TEST(JournalSinkSend, AnEntryTheJournalRefusesGoesToTheFallback) {
  test::LogCapture fallback;
  JournalSink sink([](const struct iovec*, int) { return -ENOENT; }, fallback);  // no journal socket
  sink.write(job_record());
  ASSERT_EQ(fallback.records().size(), 1u);
  EXPECT_EQ(fallback.records()[0].fields.job_id, 12);
  EXPECT_EQ(text(fallback.records()[0]), "job 12 (knit, knitter): failed: knitter: the pattern is 230 stitches wide");
}

}  // namespace
}  // namespace atelier::log
