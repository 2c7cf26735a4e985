// The character-counting window of GRBL streaming: the host may have at most `budget` bytes
// of lines (each with its newline) in the controller's receive buffer; every ok/error frees
// the oldest line. Budget = receive buffer bytes - 1 (127 for GRBL 1.1h's 128).
// Pure value type; not thread-safe.
#pragma once

#include <cstddef>
#include <deque>

namespace atelier::grbl {

class CharCounter {
 public:
  explicit CharCounter(size_t budget) : budget_(budget) {}

  // Whether a line of `bytes_with_newline` may be sent now without overflowing the buffer.
  bool fits(size_t bytes_with_newline) const { return in_flight_ + bytes_with_newline <= budget_; }
  // Records a line sent (its size including the newline).
  void sent(size_t bytes_with_newline);
  // An ok/error arrived: frees the oldest line in flight and returns its size.
  // Throws std::logic_error when nothing is in flight (a reply GRBL never owed us).
  size_t acked();
  size_t in_flight() const { return in_flight_; }
  size_t lines_in_flight() const { return sizes_.size(); }
  size_t budget() const { return budget_; }
  void clear();  // after a soft reset GRBL drops its receive buffer

 private:
  size_t budget_;
  size_t in_flight_ = 0;
  std::deque<size_t> sizes_;
};

}  // namespace atelier::grbl
