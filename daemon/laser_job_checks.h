// Checks a laser job against the controller it is about to run on, before anything is sent:
// the power scale it was made for ($30) and the machine's travel ($130/$131). Pure.
#pragma once

#include <optional>
#include <string>

#include "drivers/grbl/program.h"
#include "drivers/grbl/session.h"

namespace atelier {

// The reason `program` (read from `file`) must not run on a controller with `info`, or
// nullopt when it fits. Travel is checked only when the controller reports it (> 0): a job
// in positive coordinates must lie in [0, $130] x [0, $131]; one in negative coordinates
// (machines homed at the rear or right) in [-$130, 0] x [-$131, 0].
std::optional<std::string> job_fit_problem(const grbl::Program& program, const grbl::MachineInfo& info,
                                           const std::string& file);

// The rapid (G0) rate for time estimates in mm/min: the slower of $110 and $111, or 6000 when
// the controller does not say.
double rapid_rate(const grbl::MachineInfo& info);

}  // namespace atelier
