// The job store's schema history (daemon/store_schema.h): migration steps numbered in order.
#include <gtest/gtest.h>

#include "daemon/store_schema.h"
#include "tests/unit/daemon/store_fixture.h"

namespace atelier {
namespace {

using test::StoreTest;

TEST_F(StoreTest, MigrationStepsAreNumberedInOrder) {
  const auto& steps = schema_migrations();
  ASSERT_FALSE(steps.empty());
  for (size_t i = 0; i < steps.size(); ++i) EXPECT_EQ(steps[i].to_version, static_cast<int>(i) + 1);
  EXPECT_EQ(latest_schema_version(), steps.back().to_version);
}

}  // namespace
}  // namespace atelier
