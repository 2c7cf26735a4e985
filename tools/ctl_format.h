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

// `s` cut to at most `max_chars` UTF-8 characters, the last three being "..." when cut.
std::string truncate_chars(const std::string& s, std::size_t max_chars);

// "2024-05-01T12:03:04Z" as local "2024-05-01 14:03:04" (or "14:03:04" without the date);
// text that does not parse is returned unchanged.
std::string local_time(const std::string& iso_utc, bool with_date = true);

// `list`: aligned table ID KIND STATE PROGRESS UPDATED NAME REASON, or "no jobs".
std::string format_job_table(const nlohmann::json& jobs);
// `show`: "key: value" lines, then outputs and history.
std::string format_job_details(const nlohmann::json& job);
// `status`: daemon, spool, queue counts per state, devices.
std::string format_status(const nlohmann::json& status);
// `devices`: aligned table NAME DRIVER PORT STATE JOB, or "no devices configured".
std::string format_devices(const nlohmann::json& devices);
// One `watch` event: "<time> job 12 cat.jpg: converting -> completed (reason)".
std::string format_event(const nlohmann::json& event);
// A verb that returns one job (submit, start, cancel, retry, resume): "job 12 cat.jpg: queued".
std::string format_job_line(const nlohmann::json& job);
// `wood`: what was done (if anything), then the sheets as an aligned table ID SIZE_MM DPI
// USED FREE_MM2 PIECES JOBS, or "no veneer sheets".
std::string format_wood(const nlohmann::json& result);
// Anything else (frame): strings as is, arrays of objects as a table, objects as
// key: value lines, other values as JSON.
std::string format_value(const nlohmann::json& value);

}  // namespace atelier::ctl
