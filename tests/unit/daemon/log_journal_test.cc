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

#include <systemd/sd-journal.h>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "daemon/log_journal.h"
#include "tests/e2e/daemon_harness.h"
#include "tests/support/log_capture.h"

namespace atelier::log {
namespace {

using ::testing::AllOf;
using ::testing::Contains;
using ::testing::EndsWith;
using ::testing::HasSubstr;
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
  EXPECT_THAT(fields, Contains(AllOf(StartsWith("CODE_FILE="), EndsWith("tests/unit/daemon/log_journal_test.cc"),
                                     Not(HasSubstr("../")))));
  EXPECT_THAT(fields, Contains("CODE_LINE=" + std::to_string(job_record().where.line())));
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

// Where journald runs (the boot test's root, a developer's machine), an entry sent through the
// real sd_journal_sendv can be read back with its fields. Skipped without a journal.
TEST(JournalSinkSend, TheRealJournalKeepsTheEntryWithItsFields) {
  if (::access("/run/systemd/journal/socket", F_OK) != 0) GTEST_SKIP() << "no journald on this machine";
  test::LogCapture fallback;
  JournalSink sink(sd_journal_sender(), fallback);
  // A job id no daemon hands out, so the entry is ours alone.
  const int64_t marker = 9000000000000 + static_cast<int64_t>(::getpid());
  sink.write(Record{Priority::info, "completed: sent by atelier_tests", {marker, "knit", "knitter", "completed"},
                    std::source_location::current()});
  ASSERT_TRUE(fallback.records().empty()) << "the journal refused the entry";

  sd_journal* journal = nullptr;
  if (sd_journal_open(&journal, SD_JOURNAL_LOCAL_ONLY) < 0) GTEST_SKIP() << "the journal cannot be read here";
  std::unique_ptr<sd_journal, decltype(&sd_journal_close)> closer(journal, sd_journal_close);
  if (sd_journal_next(journal) <= 0) GTEST_SKIP() << "the journal stores nothing readable here";
  const std::string match = "JOB_ID=" + std::to_string(marker);
  ASSERT_GE(sd_journal_add_match(journal, match.data(), match.size()), 0);
  sd_journal_seek_head(journal);
  bool found = false;
  for (int tries = 0; tries < 50 && !found; ++tries) {  // journald may take a moment to store it
    found = sd_journal_next(journal) > 0;
    if (!found) sd_journal_wait(journal, 200000);
  }
  ASSERT_TRUE(found) << match << " not in the journal";
  auto field = [&](const char* name) {
    const void* data = nullptr;
    size_t length = 0;
    if (sd_journal_get_data(journal, name, &data, &length) < 0) return std::string();
    return std::string(static_cast<const char*>(data), length);
  };
  EXPECT_EQ(field("MESSAGE"), "MESSAGE=job " + std::to_string(marker) + " (knit, knitter): completed: sent by atelier_tests");
  EXPECT_EQ(field("KIND"), "KIND=knit");
  EXPECT_EQ(field("DEVICE"), "DEVICE=knitter");
  EXPECT_EQ(field("STATE"), "STATE=completed");
  EXPECT_EQ(field("SYSLOG_IDENTIFIER"), "SYSLOG_IDENTIFIER=atelierd");
}

}  // namespace
}  // namespace atelier::log
