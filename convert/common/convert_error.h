// The error of a conversion that failed because of its input or parameters.
#pragma once

#include "base/error.h"

namespace atelier {

// what() is the user-facing reason and names the file ("cat.png: not a PNG or JPEG image ...").
class ConvertError : public BadInput {
 public:
  using BadInput::BadInput;
};

}  // namespace atelier
