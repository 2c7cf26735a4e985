// Human-readable renderings of control-protocol results for atelierctl. Pure functions:
// JSON in (as the daemon sent it, fields possibly missing), text out (each line ends in
// '\n'). Times from the daemon are ISO 8601 UTC and are shown in the local time zone.
#pragma once

#include <cstddef>
#include <string>

#include <nlohmann/json.hpp>

namespace atelier::ctl {

// Longest REASON shown in `list` (characters, not bytes); longer ones end in "...".
inline constexpr std::size_t kListReasonChars = 48;
// Longest LAST and DETAIL shown in `devices` (characters); `devices --json` has them whole.
inline constexpr std::size_t kDeviceTextChars = 60;

// `s` cut to at most `max_chars` UTF-8 characters, the last three being "..." when cut.
std::string truncate_chars(const std::string& s, std::size_t max_chars);

// "2024-05-01T12:03:04Z" as local "2024-05-01 14:03:04" (or "14:03:04" without the date);
// text that does not parse is returned unchanged.
std::string local_time(const std::string& iso_utc, bool with_date = true);

// `list`: aligned table ID KIND STATE PROGRESS UPDATED NAME REASON, or "no jobs". PROGRESS
// is "30/120" (rows or lines) or "30%" while converting.
std::string format_job_table(const nlohmann::json& jobs);
// The `list` result {"jobs": [...], "total": N} cut short: "showing 1000 of 1532 jobs; --all
// for every job\n"; "" when every matching job is in it.
std::string list_cut_note(const nlohmann::json& result);
// `show`: "key: value" lines (progress with its unit, "time left" of a running laser job,
// "estimated" time from its report), then outputs and history.
std::string format_job_details(const nlohmann::json& job);
// `status`: daemon, spool, queue counts per state, devices.
std::string format_status(const nlohmann::json& status);
// `devices`: aligned table NAME DRIVER PORT STATE JOB LAST DETAIL, or "no devices
// configured". JOB is "7 (40/80 lines)" with the progress' unit; LAST the outcome of the last
// job or framing, DETAIL what the device is doing (lines and time left, held, a pause).
std::string format_devices(const nlohmann::json& devices);
// One `watch` event: "<time> job 12 cat.jpg: converting -> completed (reason)". <time> is
// the event's "at" (when it happened), else now.
std::string format_event(const nlohmann::json& event);
// A verb that returns one job (submit, start, cancel, retry, resume, hold, frame): the job as
// it is after the command, "job 12 cat.jpg: running (running on laser)"; with the daemon's
// "effect" (under way, not yet in the job's reason) "job 7 a.svg: running, held (...)".
std::string format_job_line(const nlohmann::json& job);
// `cancel --all`: one line per job, then "canceled N jobs" (or "no unfinished jobs to cancel").
std::string format_cancel_all(const nlohmann::json& result);
// `wood`: what was done (if anything), then the sheets as an aligned table ID SIZE_MM DPI
// USED FREE_MM2 PIECES JOBS, or "no veneer sheets".
std::string format_wood(const nlohmann::json& result);
// `laser unlock|home|jog|origin|send`: each line sent as "> LINE" and the controller's replies
// under it, then what was done; `laser log` ({"lines": [...]}): "TIME DEVICE uid N> LINE" and
// the replies indented, oldest first, or "no console lines".
std::string format_laser(const nlohmann::json& result);
// Anything else (frame): strings as is, arrays of objects as a table, objects as
// key: value lines, other values as JSON.
std::string format_value(const nlohmann::json& value);

}  // namespace atelier::ctl
