#include "daemon/web/password.h"

#include <crypt.h>

#include <memory>

#include "base/error.h"
#include "daemon/web/secret.h"

namespace atelier::web {

bool password_matches(const std::string& password, const std::string& hash) {
  auto data = std::make_unique<crypt_data>();  // about 32 KB: not on the stack
  const char* out = crypt_r(password.c_str(), hash.c_str(), data.get());
  // A failed crypt_r returns NULL or a string starting with '*'.
  if (!out || out[0] == '*') return false;
  return equal_in_constant_time(out, hash);
}

std::string hash_password(const std::string& password) {
  char salt[CRYPT_GENSALT_OUTPUT_SIZE];
  if (!crypt_gensalt_rn("$y$", 0, nullptr, 0, salt, sizeof salt))
    throw InternalError("cannot make a password salt (libcrypt has no yescrypt?)");
  auto data = std::make_unique<crypt_data>();
  const char* out = crypt_r(password.c_str(), salt, data.get());
  if (!out || out[0] == '*') throw InternalError("cannot hash the password (libcrypt)");
  return out;
}

}  // namespace atelier::web
