// base/error.h: every project exception is an atelier::Error of the right category, so one
// catch clause can tell a bad file from a failing machine, a stop and a bug.
#include <gtest/gtest.h>

#include <string>

#include "base/error.h"
#include "convert/common/convert_error.h"
#include "convert/common/param_table.h"
#include "daemon/store.h"
#include "drivers/grbl/session.h"
#include "drivers/transport.h"

namespace atelier {
namespace {

template <class E>
ErrorCategory category_of(const E& thrown) {
  try {
    throw thrown;
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), std::string(thrown.what()));  // the message is kept
    return e.category();
  }
}

TEST(Error, EachProjectExceptionCarriesItsCategory) {
  EXPECT_EQ(category_of(ConvertError("cat.png: not an image")), ErrorCategory::bad_input);
  EXPECT_EQ(category_of(ParamError("job.toml:3: key 'width': must be 20..400")), ErrorCategory::bad_input);
  EXPECT_EQ(category_of(LinkLost("/dev/ttyACM0: unplugged")), ErrorCategory::device);
  EXPECT_EQ(category_of(grbl::GrblAlarm(2)), ErrorCategory::device);
  EXPECT_EQ(category_of(grbl::Silent("laser stopped answering")), ErrorCategory::device);
  EXPECT_EQ(category_of(grbl::Canceled("stream canceled")), ErrorCategory::cancelled);
  EXPECT_EQ(category_of(StoreError("jobs.sqlite: disk full")), ErrorCategory::internal);
}

TEST(Error, IsStillAStdRuntimeErrorForCodeThatCatchesThose) {
  try {
    throw LinkLost("/dev/ttyUSB0: gone");
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "/dev/ttyUSB0: gone");
  }
}

}  // namespace
}  // namespace atelier
