// The 256-row block arithmetic of an AYAB session: the firmware numbers the lines it requests
// modulo 256, counting from 0 after each reqStart; the host keeps the absolute count.
// Pure value type; not thread-safe.
#pragma once

#include <cstdint>

namespace atelier::ayab {

class LineTracker {
 public:
  enum class Kind {
    next,             // the line after the last one requested (or line 0 first)
    repeat,           // the line requested last, again (the firmware rejected our answer)
    out_of_sequence,  // anything else: the host must abort
  };
  struct Result {
    Kind kind;
    int line;  // absolute session line for next/repeat; for out_of_sequence the line expected
  };

  // Classifies a reqLine carrying `wire` (line number modulo 256) and advances on `next`.
  Result on_request(uint8_t wire);
  // Absolute session line expected next (= lines requested so far).
  int expected() const { return next_; }

 private:
  int next_ = 0;
};

}  // namespace atelier::ayab
