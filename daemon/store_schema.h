// The job store's schema history: an ordered list of migration steps.
//
// The database records its version in PRAGMA user_version (0 = empty file). Step i takes the
// schema from version i to version i+1 and runs in its own transaction together with the
// user_version bump, so a crash leaves the database at a whole version. Steps are append-only:
// never edit a released step (databases in the field were built by it); add a new one.
#pragma once

#include <vector>

namespace atelier {

struct SchemaMigration {
  int to_version;           // the version the database has after this step (1, 2, ...)
  const char* description;  // one line, for error messages
  const char* sql;          // one or more statements; no bound values (schema only)
};

// All steps, oldest first; migrations()[i].to_version == i + 1. Static storage, never freed.
const std::vector<SchemaMigration>& schema_migrations();

// The version the code builds and understands (the last step's to_version).
int latest_schema_version();

}  // namespace atelier
