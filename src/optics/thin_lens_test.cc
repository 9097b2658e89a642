#include "optics/thin_lens.h"

#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"

namespace blurcue::optics {
namespace {

// The thesis's optics (Table 4.2): f = 21 mm, N = 5.6 so D = 3.75 mm, sigma = 5.1e-3 mm per pixel.
const Lens kThesis{21.0, 21.0 / 5.6, 5.1e-3};
constexpr double kInf = std::numeric_limits<double>::infinity();

// The textbook blur-circle diameter c = D f |u - u0| / (u (u0 - f)), written out here on its own so the tests do
// not check the code against itself; the radius in pixels is c / 2 / pitch.
double TextbookRadiusPx(const Lens& lens, double u0, double u) {
  const double D = lens.aperture_mm, f = lens.focal_length_mm;
  const double c = std::isinf(u0) ? D * f / u : D * f * std::abs(u - u0) / (u * (u0 - f));
  return c / 2 / lens.pixel_pitch_mm;
}

// Runs fn, expects Error(kDomain) whose message contains `text`; returns the message.
template <typename Fn>
std::string ExpectDomainError(Fn fn, const std::string& text) {
  try {
    const double v = fn();
    ADD_FAILURE() << "expected Error(kDomain), got the value " << v;
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kDomain) << e.what();
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    return e.what();
  }
  return "";
}

TEST(ThinLens, ThesisNumbers) {
  // r1 = 8 px at edge 1 (342.3 mm) gives r2 = 16.61 px at edge 11 (527.3 mm), worked by hand from eq. 3.7:
  // ratio = 342.3 * 506.3 / (527.3 * 321.3) = 1.0229313, r2 = (1.0229313 * 3.8316 - 3.75) / 0.0102 = 16.614.
  EXPECT_NEAR(Eq37Px(kThesis, 342.3, 8.0, 527.3), 16.61, 0.01);
}

TEST(ThinLens, MatchesTextbookBlurCircle) {
  for (double u0 : {258.0, 342.3, 430.0, 1000.0, 5000.0})
    for (double u : {50.0, 200.0, 342.3, 400.0, 527.3, 2000.0})
      EXPECT_NEAR(BlurRadiusPx(kThesis, u0, u), TextbookRadiusPx(kThesis, u0, u), 1e-9)
          << "u0 = " << u0 << ", u = " << u;
}

TEST(ThinLens, SignIsPositiveBeyondFocusNegativeNearerZeroOnIt) {
  EXPECT_GT(SignedBlurRadiusPx(kThesis, 400.0, 527.3), 0);
  EXPECT_LT(SignedBlurRadiusPx(kThesis, 400.0, 342.3), 0);
  EXPECT_NEAR(SignedBlurRadiusPx(kThesis, 400.0, 400.0), 0.0, 1e-12);
}

TEST(ThinLens, Eq37AgreesWithThinLensWhenBothPointsAreBeyondFocus) {
  for (double u0 : {100.0, 258.0, 342.3}) {
    const double r1 = TextbookRadiusPx(kThesis, u0, 342.3);
    for (double u2 : {342.3, 400.0, 527.3, 3000.0})
      EXPECT_NEAR(Eq37Px(kThesis, 342.3, r1, u2), TextbookRadiusPx(kThesis, u0, u2), 1e-9)
          << "u0 = " << u0 << ", u2 = " << u2;
  }
}

TEST(ThinLens, SignedEq37AgreesOnBothSidesOfFocus) {
  const double u0 = 430.0;
  const double r1 = -TextbookRadiusPx(kThesis, u0, 342.3);  // the reference is nearer than focus
  for (double u2 : {300.0, 342.3, 400.0, 430.0, 480.0, 527.3}) {
    const double expected = (u2 < u0 ? -1 : 1) * TextbookRadiusPx(kThesis, u0, u2);
    EXPECT_NEAR(Eq37SignedPx(kThesis, 342.3, r1, u2), expected, 1e-9) << "u2 = " << u2;
    EXPECT_NEAR(Eq37SignedPx(kThesis, 342.3, r1, u2), SignedBlurRadiusPx(kThesis, u0, u2), 1e-9) << "u2 = " << u2;
  }
}

TEST(ThinLens, FocusFromReferenceRoundTrips) {
  for (double u0 : {60.0, 258.0, 430.0, 1000.0, 1e5})
    for (double u1 : {342.3, 527.3}) {
      const double r1 = SignedBlurRadiusPx(kThesis, u0, u1);
      EXPECT_NEAR(FocusFromReferenceMm(kThesis, u1, r1), u0, 1e-7 * u0) << "u0 = " << u0 << ", u1 = " << u1;
    }
}

TEST(ThinLens, ThesisReferenceImpliesFocusNearerThanEdgeOne) {
  // 8 px of blur at edge 1 with both points assumed beyond focus puts focus in front of the board.
  const double u0 = FocusFromReferenceMm(kThesis, 342.3, 8.0);
  EXPECT_LT(u0, 342.3);
  EXPECT_NEAR(TextbookRadiusPx(kThesis, u0, 342.3), 8.0, 1e-9);
}

TEST(ThinLens, FocusAtInfinity) {
  for (double u : {100.0, 342.3, 527.3}) {
    const double expected = kThesis.aperture_mm * kThesis.focal_length_mm / (2 * u * kThesis.pixel_pitch_mm);
    EXPECT_NEAR(BlurRadiusPx(kThesis, kInf, u), expected, 1e-9) << "u = " << u;
    // Every finite point is nearer than a focus at infinity.
    EXPECT_LT(SignedBlurRadiusPx(kThesis, kInf, u), 0);
    EXPECT_TRUE(std::isinf(FocusFromReferenceMm(kThesis, u, -expected))) << "u = " << u;
  }
}

TEST(ThinLens, PointAtOrInsideFocalLengthIsDomainError) {
  for (double u : {21.0, 10.0, 0.0, -5.0}) {
    ExpectDomainError([&] { return SignedBlurRadiusPx(kThesis, 400.0, u); }, "focal length");
    ExpectDomainError([&] { return Eq37Px(kThesis, 342.3, 8.0, u); }, "u2 = ");
    ExpectDomainError([&] { return Eq37SignedPx(kThesis, 342.3, 8.0, u); }, "u2 = ");
  }
}

TEST(ThinLens, FocusAtOrInsideFocalLengthIsDomainError) {
  for (double u0 : {21.0, 20.0, 0.0})
    ExpectDomainError([&] { return SignedBlurRadiusPx(kThesis, u0, 400.0); }, "focus distance");
}

TEST(ThinLens, ReferenceAtFocalLengthIsDomainError) {
  // u1 = f would divide by zero in eq. 3.7.
  ExpectDomainError([] { return Eq37Px(kThesis, 21.0, 8.0, 527.3); }, "u1 = 21 mm");
  ExpectDomainError([] { return Eq37SignedPx(kThesis, 21.0, 8.0, 527.3); }, "u1 = 21 mm");
  ExpectDomainError([] { return FocusFromReferenceMm(kThesis, 21.0, 8.0); }, "u1 = 21 mm");
}

TEST(ThinLens, PublishedEq37RejectsNegativeReferenceRadius) {
  ExpectDomainError([] { return Eq37Px(kThesis, 342.3, -1.0, 527.3); }, "r1 = -1 px");
}

TEST(ThinLens, PublishedEq37RejectsPointNearerThanFocus) {
  // The thesis reference puts focus at ~258 mm; 230 mm is in front of it.
  const std::string message =
      ExpectDomainError([] { return Eq37Px(kThesis, 342.3, 8.0, 230.0); }, "nearer than the focus plane");
  EXPECT_NE(message.find("signed form"), std::string::npos) << message;
  // A reference in perfect focus: every nearer point is in front of focus.
  ExpectDomainError([] { return Eq37Px(kThesis, 342.3, 0.0, 300.0); }, "nearer than the focus plane");
}

TEST(ThinLens, ImpossibleNearSideReferenceIsDomainError) {
  // More blur in front of focus than even a focus at infinity makes (D f / (2 u pitch) = 22.6 px at 342.3 mm).
  ExpectDomainError([] { return FocusFromReferenceMm(kThesis, 342.3, -30.0); }, "focused at infinity");
}

TEST(ThinLens, NeverReturnsNaN) {
  // Every combination either throws Error or gives a finite number (or +infinity for a focus distance).
  const double values[] = {-100, 0, 1e-9, 20.999999, 21, 21.000001, 22, 100, 258, 342.3, 527.3, 1e6, 1e12, kInf};
  const double radii[] = {-100, -22.6, -8, 0, 1e-9, 8, 16.61, 100};
  int finite = 0;
  for (double a : values)
    for (double b : values) {
      try {
        const double r = SignedBlurRadiusPx(kThesis, a, b);
        EXPECT_TRUE(std::isfinite(r)) << "focus " << a << ", u " << b;
        ++finite;
      } catch (const Error&) {
      }
      for (double r1 : radii) {
        try {
          EXPECT_TRUE(std::isfinite(Eq37SignedPx(kThesis, a, r1, b))) << a << " " << r1 << " " << b;
        } catch (const Error&) {
        }
        try {
          EXPECT_TRUE(std::isfinite(Eq37Px(kThesis, a, r1, b))) << a << " " << r1 << " " << b;
        } catch (const Error&) {
        }
        try {
          EXPECT_FALSE(std::isnan(FocusFromReferenceMm(kThesis, a, r1))) << a << " " << r1;
        } catch (const Error&) {
        }
      }
    }
  EXPECT_GT(finite, 0);
  // Focus at infinity with finite points.
  for (double u : values)
    try {
      EXPECT_TRUE(std::isfinite(SignedBlurRadiusPx(kThesis, kInf, u))) << "u " << u;
    } catch (const Error&) {
    }
}

// A point (u, u1 or u2) at +infinity has a finite blur circle, R = D f / (2 (u0 - f)), not inf/inf.
TEST(ThinLens, PointAtInfinityIsFinite) {
  const double expected = kThesis.aperture_mm * kThesis.focal_length_mm / (2 * (430.0 - 21.0)) /
                          kThesis.pixel_pitch_mm;
  EXPECT_NEAR(SignedBlurRadiusPx(kThesis, 430.0, kInf), expected, 1e-9);
  EXPECT_FALSE(std::isnan(Eq37SignedPx(kThesis, 342.3, 8.0, kInf)));
  EXPECT_FALSE(std::isnan(FocusFromReferenceMm(kThesis, kInf, 8.0)));
}

}  // namespace
}  // namespace blurcue::optics
