// Secrets of the web server: random tokens (sessions, CSRF) and comparisons that take the
// same time whatever matches, so a token cannot be guessed byte by byte from response times.
// Threading: stateless; any thread.
#pragma once

#include <cstddef>
#include <string>

namespace atelier::web {

// `bytes` random bytes from the kernel (getrandom), as lowercase hex (2 x bytes characters).
// Throws InternalError if the kernel gives none.
std::string random_token(size_t bytes = 32);

// a == b, in time that depends only on their lengths.
bool equal_in_constant_time(const std::string& a, const std::string& b);

}  // namespace atelier::web
