// The clear sky's scattering (cpu/sky_scattering.hpp), on numbers: blue overhead by day, the
// horizon under a low sun reddened towards it, twilight after sunset, dark at night.
#include "server/render/cpu/sky_scattering.hpp"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

namespace downpour::render {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

double luminance(const glm::dvec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

TEST(SkyScatteringTest, TheDaySkyIsBlueOverheadAndPalerAtTheHorizon) {
  const glm::dvec3 zenith = clear_sky_radiance(60.0, 90.0 * kDeg, 0.0);
  const glm::dvec3 horizon = clear_sky_radiance(60.0, 2.0 * kDeg, 180.0 * kDeg);
  EXPECT_GT(zenith.z, 2.0 * zenith.x);
  EXPECT_GT(horizon.x / horizon.z, zenith.x / zenith.z) << "paler (whiter) low down";
}

TEST(SkyScatteringTest, ALowSunReddensTheHorizonTowardsIt) {
  const glm::dvec3 toward = clear_sky_radiance(3.0, 2.0 * kDeg, 0.0);
  const glm::dvec3 away = clear_sky_radiance(3.0, 2.0 * kDeg, 180.0 * kDeg);
  const glm::dvec3 noon = clear_sky_radiance(60.0, 2.0 * kDeg, 0.0);
  EXPECT_GT(toward.x, 3.0 * toward.z);
  EXPECT_GT(luminance(toward), 2.0 * luminance(away));
  EXPECT_LT(noon.x, noon.z);
}

TEST(SkyScatteringTest, TwilightGlowsLowTowardsTheSunAndNightIsDark) {
  const glm::dvec3 glow = clear_sky_radiance(-3.0, 2.0 * kDeg, 0.0);
  const glm::dvec3 zenith = clear_sky_radiance(-3.0, 90.0 * kDeg, 0.0);
  EXPECT_GT(glow.x, 5.0 * glow.z);
  EXPECT_GT(luminance(glow), 3.0 * luminance(zenith));
  // Overhead the ozone keeps it blue while the low sky is red.
  EXPECT_GT(zenith.z, zenith.x * 0.9);
  EXPECT_LT(luminance(clear_sky_radiance(-18.0, 30.0 * kDeg, 0.0)), 1e-3 * luminance(glow));
}

TEST(SkyScatteringTest, TheTableHoldsTheRadianceByAzimuthAndElevation) {
  const auto table = clear_sky_table(10.0);
  ASSERT_EQ(table.size(), static_cast<std::size_t>(kSkyTableWidth * kSkyTableHeight));
  // Column 0 towards the sun, the last away; the top row the zenith, alike in every column.
  const glm::vec3 toward = table[kSkyTableWidth * 2], away = table[kSkyTableWidth * 3 - 1];
  EXPECT_GT(luminance(glm::dvec3(toward)), 2.0 * luminance(glm::dvec3(away)));
  const std::size_t top = static_cast<std::size_t>(kSkyTableHeight - 1) * kSkyTableWidth;
  EXPECT_NEAR(table[top].z, table[top + kSkyTableWidth - 1].z, 1e-3 * table[top].z);
}

}  // namespace
}  // namespace downpour::render
