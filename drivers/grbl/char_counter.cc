#include "drivers/grbl/char_counter.h"

#include <stdexcept>

namespace atelier::grbl {

void CharCounter::sent(size_t bytes_with_newline) {
  sizes_.push_back(bytes_with_newline);
  in_flight_ += bytes_with_newline;
}

size_t CharCounter::acked() {
  if (sizes_.empty()) throw std::logic_error("GRBL answered a line that was never sent (ok/error with nothing in flight)");
  const size_t n = sizes_.front();
  sizes_.pop_front();
  in_flight_ -= n;
  return n;
}

void CharCounter::clear() {
  sizes_.clear();
  in_flight_ = 0;
}

}  // namespace atelier::grbl
