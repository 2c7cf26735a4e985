// GRBL 1.1h's numbered error and alarm codes as words (from GRBL's own
// doc/csv/error_codes_en_US.csv and alarm_codes_en_US.csv), for messages a user reads.
// Pure, thread-safe.
#pragma once

#include <string>

namespace atelier::grbl {

// "invalid target: motion command target is invalid" for 33; "unknown error code" outside 1..38.
std::string error_meaning(int code);
// "soft limit: G-code motion target exceeds machine travel; ..." for 2; "unknown alarm code"
// outside 1..10.
std::string alarm_meaning(int code);
// What happened and what the operator must do now, for ALARM:N (1..10): e.g. 1, hard limit:
// "... check the machine, then home it ($H)". A limit alarm is never called safe to unlock.
std::string alarm_advice(int code);

}  // namespace atelier::grbl
