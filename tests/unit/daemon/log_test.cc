// The log's records and its plain stderr lines: a record about a job names it with its kind
// and device in front of the message, a device alone is named as a device, warnings and
// errors say so, debug records are dropped unless --verbose, and the call site is the
// record's location (the journal's CODE_FILE/CODE_LINE).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fcntl.h>
#include <unistd.h>

#include <string>

#include "daemon/log.h"
#include "tests/e2e/daemon_harness.h"
#include "tests/support/log_capture.h"

namespace atelier::log {
namespace {

using ::testing::EndsWith;

Record record(Priority p, const std::string& message, Fields fields = {}) {
  return Record{p, message, std::move(fields), std::source_location::current()};
}

// What `sink` wrote to a file standing for stderr.
std::string written_by(bool priority_prefixes, const Record& r) {
  test::TempDir tmp;
  const std::string file = (tmp.path() / "stderr").string();
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  EXPECT_GE(fd, 0);
  StderrSink(fd, priority_prefixes).write(r);
  ::close(fd);
  return test::read_file(file);
}

TEST(LogText, AJobIsNamedWithItsKindAndDevice) {
  EXPECT_EQ(text(record(Priority::info, "completed: knitted 200 rows on knitter", {12, "knit", "knitter", "completed"})),
            "job 12 (knit, knitter): completed: knitted 200 rows on knitter");
  EXPECT_EQ(text(record(Priority::info, "converting", {12, "knit", "", "converting"})), "job 12 (knit): converting");
  EXPECT_EQ(text(record(Priority::error, "cannot record the failure", {12, "", "", ""})),
            "job 12: cannot record the failure");
}

TEST(LogText, ADeviceAloneIsNamedAsADevice) {
  EXPECT_EQ(text(record(Priority::info, "offline (not connected)", device_fields("laser"))),
            "device laser: offline (not connected)");
  EXPECT_EQ(text(record(Priority::info, "atelierd ready")), "atelierd ready");
}

TEST(LogStderr, PlainLinesSayWarningAndErrorAndNothingForInfo) {
  EXPECT_EQ(written_by(false, record(Priority::warning, "failed: not an image", {3, "knit", "", "failed"})),
            "warning: job 3 (knit): failed: not an image\n");
  EXPECT_EQ(written_by(false, record(Priority::error, "poll: Bad file descriptor")),
            "error: poll: Bad file descriptor\n");
  EXPECT_EQ(written_by(false, record(Priority::info, "completed", {3, "knit", "", "completed"})),
            "job 3 (knit): completed\n");
}

TEST(LogStderr, OnTheJournalsStreamLinesCarryThePriorityPrefixJournaldReads) {
  EXPECT_EQ(written_by(true, record(Priority::warning, "failed: not an image", {3, "knit", "", "failed"})),
            "<4>job 3 (knit): failed: not an image\n");
  EXPECT_EQ(written_by(true, record(Priority::info, "stopped")), "<6>stopped\n");
}

TEST(LogSink, RecordsReachTheInstalledSinkWithTheirFieldsAndCallSite) {
  test::LogCapture capture;
  const int line = __LINE__ + 1;
  info("running: knitting on knitter", {7, "knit", "knitter", "running"});
  ASSERT_EQ(capture.records().size(), 1u);
  const Record r = capture.records().front();
  EXPECT_EQ(r.priority, Priority::info);
  EXPECT_EQ(r.message, "running: knitting on knitter");
  EXPECT_EQ(r.fields.job_id, 7);
  EXPECT_EQ(r.fields.kind, "knit");
  EXPECT_EQ(r.fields.device, "knitter");
  EXPECT_EQ(r.fields.state, "running");
  EXPECT_THAT(std::string(r.where.file_name()), EndsWith("log_test.cc"));
  EXPECT_EQ(r.where.line(), static_cast<unsigned>(line));
}

TEST(LogSink, DebugRecordsAreDroppedUnlessVerbose) {
  test::LogCapture capture;
  debug("claim hook: intent");
  EXPECT_TRUE(capture.records().empty());
  set_verbose(true);
  debug("claim hook: intent");
  set_verbose(false);
  ASSERT_EQ(capture.records().size(), 1u);
  EXPECT_EQ(capture.records().front().priority, Priority::debug);
}

}  // namespace
}  // namespace atelier::log
