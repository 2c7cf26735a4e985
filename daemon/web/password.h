// Password hashes for page logins ([web.users]): crypt(3) from libxcrypt (Debian's libcrypt),
// so the hashes are those of /etc/shadow, `mkpasswd -m yescrypt` and `openssl passwd -6`.
// Threading: both functions are reentrant (crypt_r with a buffer of their own).
#pragma once

#include <string>

namespace atelier::web {

// Whether `password` matches `hash` ("$y$...", "$6$...", "$2b$..."). False for a hash
// crypt(3) does not understand; never throws.
bool password_matches(const std::string& password, const std::string& hash);

// A new yescrypt hash of `password` with a random salt. Throws InternalError if libcrypt
// cannot make one.
std::string hash_password(const std::string& password);

}  // namespace atelier::web
