// Reading a job file's kind (convert/job_file_kind.h), as `atelier-convert --job-kind` does:
// the kind, or a reason with the file's name, line and column that quotes nothing of it.
#include <gtest/gtest.h>

#include "convert/job_file_kind.h"
#include "tests/e2e/daemon_harness.h"

namespace atelier {
namespace {

TEST(JobFileKind, ParseErrorsKeepTheirGrammarButLoseTheInput) {
  EXPECT_EQ(description_without_content("Error while parsing key-value pair: expected '=', saw ':'"),
            "Error while parsing key-value pair: expected '='");
  EXPECT_EQ(description_without_content("Error while parsing key-value pair: cannot redefine existing integer 'secret'"),
            "Error while parsing key-value pair: cannot redefine existing integer '...'");
  EXPECT_EQ(description_without_content("unterminated 'quote"), "unterminated");
}

TEST(JobFileKind, TheKindOrWhyThereIsNone) {
  test::TempDir tmp;
  test::write_file(tmp.path() / "a.toml", "kind = \"lace\"\n");
  test::write_file(tmp.path() / "b.toml", "width = 3\n");
  test::write_file(tmp.path() / "c.toml", "kind = \"lacy\"\n");
  test::write_file(tmp.path() / "d.toml", "kind = \"knit\"\n");
  test::write_file(tmp.path() / "e.toml", "x = \n");
  EXPECT_EQ(read_job_file_kind(tmp.path() / "a.toml", "a.toml").kind, "lace");
  EXPECT_NE(read_job_file_kind(tmp.path() / "b.toml", "b.toml").problem.find("b.toml: a job file needs kind"), std::string::npos);
  EXPECT_NE(read_job_file_kind(tmp.path() / "c.toml", "c.toml").problem.find("unknown kind 'lacy'"), std::string::npos);
  EXPECT_NE(read_job_file_kind(tmp.path() / "d.toml", "d.toml").problem.find("converts an image"), std::string::npos);
  EXPECT_EQ(read_job_file_kind(tmp.path() / "e.toml", "e.toml").problem.rfind("e.toml:1:", 0), 0u);
}

}  // namespace
}  // namespace atelier
