// Tests that draw: one offscreen OpenGL 4.5 context (EGL surfaceless, no X server) per test
// binary, made on first use. A machine that cannot make one at all skips these tests with the
// reason; anything that fails after a context exists is a failure, not a skip.
// Set BALLPIT_TEST_IMAGES=DIR to keep every image a test draws, for looking at.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <optional>
#include <string>

#include "app/gl_context.h"
#include "app/image.h"
#include "app/offscreen_context.h"

namespace ballpit::test {

class GlTest : public ::testing::Test {
 public:
  // Writes the image to $BALLPIT_TEST_IMAGES/name.png when that variable is set.
  static void keep(const Image& image, const std::string& name) {
    if (const char* dir = std::getenv("BALLPIT_TEST_IMAGES")) write_png(std::string(dir) + "/" + name + ".png", image);
  }

 protected:
  void SetUp() override {
    static std::unique_ptr<OffscreenContext> context;
    static std::optional<std::string> unavailable;
    if (!context && !unavailable) {
      try {
        context = std::make_unique<OffscreenContext>();
      } catch (const GlUnavailable& e) {
        unavailable = e.what();
      }
    }
    if (unavailable) GTEST_SKIP() << "no OpenGL 4.5 context can be made here: " << *unavailable;
    context->make_current();
  }
};

}  // namespace ballpit::test
