// A decoded image a model's material samples: rows top to bottom, four bytes a texel (sRGB
// red, green, blue, then linear alpha), as glTF's baseColorTexture means them.
#pragma once

#include <cstdint>
#include <vector>

namespace ballpit {

struct Texture {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;  // width * height * 4 bytes
};

}  // namespace ballpit
