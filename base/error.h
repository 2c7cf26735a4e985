// The one base of every atelier exception.
//
// what() is the message a user sees and names the file, key or device it is about; category()
// says what kind of failure it is, so a caller that only needs to decide "the input was bad,
// the machine failed, somebody stopped it, or we have a bug" catches atelier::Error once and
// switches on the category instead of catching a ladder of classes.
//
// Each project exception derives from one of the four category classes below (ConvertError
// and ParamError from BadInput, LinkLost and the GRBL/AYAB errors from DeviceError, ...).
// Header-only; pure (no I/O), so algorithms/ may throw these too.
#pragma once

#include <stdexcept>
#include <string>

namespace atelier {

enum class ErrorCategory {
  bad_input,  // a file, parameter or request the user can fix ("cat.png: not an image")
  device,     // a machine, link or service failed or went away (serial, USB, a socket)
  cancelled,  // an operator or shutdown stopped the work on purpose
  internal,   // the store, the installation or a bug; not the user's doing
};

class Error : public std::runtime_error {
 public:
  Error(ErrorCategory category, const std::string& what)
      : std::runtime_error(what), category_(category) {}
  ErrorCategory category() const noexcept { return category_; }

 private:
  ErrorCategory category_;
};

class BadInput : public Error {
 public:
  explicit BadInput(const std::string& what) : Error(ErrorCategory::bad_input, what) {}
};
class DeviceError : public Error {
 public:
  explicit DeviceError(const std::string& what) : Error(ErrorCategory::device, what) {}
};
class Cancelled : public Error {
 public:
  explicit Cancelled(const std::string& what) : Error(ErrorCategory::cancelled, what) {}
};
class InternalError : public Error {
 public:
  explicit InternalError(const std::string& what) : Error(ErrorCategory::internal, what) {}
};

}  // namespace atelier
