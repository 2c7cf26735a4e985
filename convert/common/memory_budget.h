// A conversion's memory budget (`[limits] job_memory_mb`, atelier-convert --memory-mb) and
// the reason a job fails with when it runs out: "NAME: needs more than N MB
// (limits.job_memory_mb)", never a bare std::bad_alloc.
//
// The budget is the process's address-space limit (RLIMIT_AS), so an allocation beyond it
// fails inside the converter (std::bad_alloc, OpenCV's StsNoMem) where it can be reported.
// A stack or mapping that cannot grow past the limit raises SIGSEGV instead; the handler
// installed here tells that case apart (the address space is within 64 MB of the limit) and
// reports it the same way, and lets every other crash die of its signal as before.
//
// Process-wide (rlimit, signal handler): call once, from main, before converting.
#pragma once

#include <cstdint>
#include <exception>
#include <string>

namespace atelier {

// Sets RLIMIT_AS to `mb` MB (soft and hard) and installs the SIGSEGV handler above, which
// writes "error: <input_name>: needs more than <mb> MB (limits.job_memory_mb)" to stderr.
// Throws std::runtime_error when the limit cannot be set.
void apply_memory_budget(uint64_t mb, const std::string& input_name);

// True for std::bad_alloc and for OpenCV's out-of-memory errors (cv::Exception with code
// StsNoMem, or "Insufficient memory" / "Failed to allocate" in its message).
bool is_out_of_memory(const std::exception& e);

// "NAME: needs more than N MB (limits.job_memory_mb)"
std::string memory_exceeded_reason(const std::string& input_name, uint64_t mb);

}  // namespace atelier
