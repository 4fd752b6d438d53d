// Packed3 must round every operation exactly as the Eigen Vec3 expression it replaces in the
// solver: that is what lets the solver switch between them without changing one bit of the
// state. Each test compares bit patterns over random vectors whose components span many
// magnitudes and signs, where a different association of the same sum would show.
#include "engine/packed3.h"

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <random>

namespace ballpit {
namespace {

constexpr int kSamples = 20000;

class Packed3Test : public ::testing::Test {
 protected:
  // Components from 1e-6 to 1e6 in magnitude, either sign, plus exact zeros of both signs.
  float component() {
    const int kind = static_cast<int>(pick_(rng_) * 16.0f);
    if (kind == 0) return 0.0f;
    if (kind == 1) return -0.0f;
    const float magnitude = std::pow(10.0f, 12.0f * pick_(rng_) - 6.0f);
    return pick_(rng_) < 0.5f ? -magnitude : magnitude;
  }
  Vec3 vec() { return {component(), component(), component()}; }

  std::mt19937 rng_{20261201};
  std::uniform_real_distribution<float> pick_{0.0f, 1.0f};
};

std::uint32_t bits(float f) { return std::bit_cast<std::uint32_t>(f); }

void expect_same_bits(const Vec3& packed, const Vec3& eigen) {
  for (int k = 0; k < 3; ++k) ASSERT_EQ(bits(packed[k]), bits(eigen[k])) << "component " << k;
}

TEST_F(Packed3Test, LoadAndStoreMoveTwelveBytesAndKeepTheirNeighbours) {
  Vec3 row[3] = {vec(), vec(), vec()};
  const Vec3 before = row[0], after = row[2], value = vec();
  Packed3::load(value).store(row[1]);
  expect_same_bits(row[1], value);
  expect_same_bits(row[0], before);
  expect_same_bits(row[2], after);
}

TEST_F(Packed3Test, ElementWiseOperationsRoundAsEigens) {
  for (int i = 0; i < kSamples; ++i) {
    const Vec3 a = vec(), b = vec();
    const float s = component();
    const Packed3 pa = Packed3::load(a), pb = Packed3::load(b);
    expect_same_bits((pa + pb).vec3(), a + b);
    expect_same_bits((pa - pb).vec3(), a - b);
    expect_same_bits((s * pa).vec3(), s * a);
    expect_same_bits((pa * s).vec3(), a * s);
    if (s != 0.0f) expect_same_bits((pa / s).vec3(), a / s);
  }
}

TEST_F(Packed3Test, DotAndNormSumAsEigenSumsThree) {
  for (int i = 0; i < kSamples; ++i) {
    const Vec3 a = vec(), b = vec();
    const Packed3 pa = Packed3::load(a), pb = Packed3::load(b);
    ASSERT_EQ(bits(dot(pa, pb)), bits(a.dot(b))) << i;
    ASSERT_EQ(bits(squared_norm(pa)), bits(a.squaredNorm())) << i;
    ASSERT_EQ(bits(norm(pa)), bits(a.norm())) << i;
  }
}

TEST_F(Packed3Test, DotIsNotTheLeftToRightSum) {
  // The test above can only fail if the order matters somewhere in its samples: this pair
  // sums to different floats as (x + y) + z and x + (y + z).
  const Vec3 a(1.0f, 1e8f, -1e8f), ones(1.0f, 1.0f, 1.0f);
  const float left_to_right = (a.x() + a.y()) + a.z();
  ASSERT_NE(bits(left_to_right), bits(a.dot(ones)));
  EXPECT_EQ(bits(dot(Packed3::load(a), Packed3::load(ones))), bits(a.dot(ones)));
}

TEST_F(Packed3Test, CrossIsEigensCross) {
  for (int i = 0; i < kSamples; ++i) {
    const Vec3 a = vec(), b = vec();
    expect_same_bits(cross(Packed3::load(a), Packed3::load(b)).vec3(), a.cross(b));
  }
}

TEST_F(Packed3Test, ZeroMeansEveryComponentIsZeroOfEitherSign) {
  EXPECT_TRUE(Packed3::load(Vec3(0.0f, -0.0f, 0.0f)).is_zero());
  EXPECT_FALSE(Packed3::load(Vec3(0.0f, 0.0f, 1e-30f)).is_zero());
  EXPECT_FALSE(Packed3::load(Vec3(std::nanf(""), 0.0f, 0.0f)).is_zero());
  for (int i = 0; i < kSamples; ++i) {
    const Vec3 a = vec();
    ASSERT_EQ(Packed3::load(a).is_zero(), a.isZero(0.0f));
  }
}

}  // namespace
}  // namespace ballpit
