// The one exception type the engine throws at its API boundary. Messages name the thing at
// fault (entity, parameter, file, field) and what was expected, so a user can fix the input
// without reading the source.
#pragma once

#include <stdexcept>
#include <string>

namespace ballpit {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace ballpit
