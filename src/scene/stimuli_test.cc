#include <unistd.h>
#include "scene/stimuli.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "core/error.h"
#include "core/image.h"

namespace blurcue::scene {
namespace {

// An icosahedron built independently of stimuli.cc: the golden-ratio vertices (0, +-1, +-phi) and cyclic
// permutations, rotated so one vertex is at +z and one of its neighbours at longitude 0 (the documented pose).
struct Icosahedron {
  std::vector<cv::Vec3d> vertices;      // unit: the 12 pentagon centres
  std::vector<cv::Vec3d> face_centres;  // unit: the 20 hexagon centres
};

Icosahedron MakeIcosahedron() {
  const double g = (1 + std::sqrt(5.0)) / 2;
  std::vector<cv::Vec3d> raw;
  for (double a : {-1.0, 1.0})
    for (double b : {-g, g}) {
      raw.emplace_back(0, a, b);
      raw.emplace_back(a, b, 0);
      raw.emplace_back(b, 0, a);
    }
  for (auto& v : raw) v = cv::normalize(v);
  const cv::Vec3d top = raw[0];
  cv::Vec3d neighbour;
  for (const auto& v : raw)
    if (v.dot(top) > 0.3 && v.dot(top) < 0.9) neighbour = v;
  const cv::Vec3d ez = top, ex = cv::normalize(neighbour - neighbour.dot(ez) * ez), ey = ez.cross(ex);
  Icosahedron ico;
  for (const auto& v : raw) ico.vertices.emplace_back(v.dot(ex), v.dot(ey), v.dot(ez));
  const auto& w = ico.vertices;
  for (size_t i = 0; i < 12; ++i)
    for (size_t j = i + 1; j < 12; ++j)
      for (size_t k = j + 1; k < 12; ++k)
        if (w[i].dot(w[j]) > 0.3 && w[j].dot(w[k]) > 0.3 && w[i].dot(w[k]) > 0.3)
          ico.face_centres.push_back(cv::normalize(w[i] + w[j] + w[k]));
  return ico;
}

// Face-plane rule with the textbook face distances of a truncated icosahedron of unit edge: circumradius
// sqrt(58 + 18 sqrt 5) / 4; a face's plane lies sqrt(R^2 - r^2) from the centre, r the face's circumradius.
bool OnPentagon(const Icosahedron& ico, const cv::Vec3d& d) {
  const double R2 = (58 + 18 * std::sqrt(5.0)) / 16, s36 = std::sin(M_PI / 5);
  const double h5 = std::sqrt(R2 - 1 / (4 * s36 * s36)), h6 = std::sqrt(R2 - 1);
  double best5 = -1e9, best6 = -1e9;
  for (const auto& v : ico.vertices) best5 = std::max(best5, v.dot(d) / h5);
  for (const auto& f : ico.face_centres) best6 = std::max(best6, f.dot(d) / h6);
  return best5 > best6;
}

// Grey level (0..255, sRGB) of the texel a direction falls on.
double TexelAt(const cv::Mat& texture, const cv::Vec3d& d) {
  const double theta = std::acos(std::clamp(d[2], -1.0, 1.0));
  double phi = std::atan2(d[1], d[0]);
  if (phi < 0) phi += 2 * M_PI;
  const int x = std::clamp(int(std::lround(phi / (2 * M_PI) * texture.cols - 0.5)), 0, texture.cols - 1);
  const int y = std::clamp(int(std::lround(theta / M_PI * texture.rows - 0.5)), 0, texture.rows - 1);
  const cv::Vec3b p = texture.at<cv::Vec3b>(y, x);
  return (p[0] + p[1] + p[2]) / 3.0;
}

double Uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

TEST(Stimuli, EveryImageHasTheRequestedSize) {
  const cv::Mat soccer = SoccerTexture(64), wood = WoodTexture(64, 1), grid = GridBoard(80), face = FacePicture(40);
  EXPECT_EQ(soccer.size(), cv::Size(64, 32));
  EXPECT_EQ(soccer.type(), CV_8UC3);
  EXPECT_EQ(wood.size(), cv::Size(64, 32));
  EXPECT_EQ(wood.type(), CV_8UC3);
  EXPECT_EQ(grid.size(), cv::Size(80, 80));
  EXPECT_EQ(grid.type(), CV_8UC4);
  EXPECT_EQ(face.size(), cv::Size(40, 60));
  EXPECT_EQ(face.type(), CV_8UC4);
}

TEST(Stimuli, BadSizeIsRefusedWithTheValue) {
  try {
    SoccerTexture(15);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("got 15"), std::string::npos) << e.what();
  }
  EXPECT_THROW(GridBoard(10), Error);
}

TEST(SoccerTexture, PentagonCentresAreDarkAndHexagonCentresLight) {
  const Icosahedron ico = MakeIcosahedron();
  ASSERT_EQ(ico.face_centres.size(), 20u);
  const cv::Mat texture = SoccerTexture(512);
  for (const auto& v : ico.vertices) EXPECT_LT(TexelAt(texture, v), 100) << "pentagon centre " << v;
  for (const auto& f : ico.face_centres) EXPECT_GT(TexelAt(texture, f), 200) << "hexagon centre " << f;
}

TEST(SoccerTexture, PanelAreasMatchTheFacePlaneRule) {
  // Expected: Monte-Carlo over directions uniform on the sphere (z uniform, longitude uniform: Archimedes).
  const Icosahedron ico = MakeIcosahedron();
  std::mt19937_64 rng(7);
  const int n = 200000;
  int on_pentagon = 0;
  for (int i = 0; i < n; ++i) {
    const double z = 2 * Uniform01(rng) - 1, phi = 2 * M_PI * Uniform01(rng), s = std::sqrt(1 - z * z);
    on_pentagon += OnPentagon(ico, cv::Vec3d(s * std::cos(phi), s * std::sin(phi), z));
  }
  const double expected = double(on_pentagon) / n;
  EXPECT_NEAR(expected, 0.28, 0.01);  // sanity of the reference itself

  // Measured without seams: texels weighted by their solid angle (cos latitude), split at the linear midpoint
  // between the panel colours so anti-aliased border texels count by coverage.
  const cv::Mat texture = SoccerTexture(512, 0.0);
  double dark = 0, total = 0;
  for (int y = 0; y < texture.rows; ++y) {
    const double weight = std::sin(M_PI * (y + 0.5) / texture.rows);
    for (int x = 0; x < texture.cols; ++x) {
      dark += weight * (SrgbToLinear(texture.at<cv::Vec3b>(y, x)[1] / 255.0) < 0.45);
      total += weight;
    }
  }
  EXPECT_NEAR(dark / total, expected, 0.005);
}

TEST(SoccerTexture, SeamsRunAlongPanelBorders) {
  // Walk the great circle from a pentagon centre to a neighbouring hexagon centre: the texture turns seam-dark
  // where the face-plane rule switches panels, and is a clean panel colour 2 deg either side.
  const Icosahedron ico = MakeIcosahedron();
  const cv::Mat texture = SoccerTexture(1024);
  const cv::Vec3d a = ico.vertices[3];
  cv::Vec3d b = ico.face_centres[0];
  for (const auto& f : ico.face_centres)
    if (f.dot(a) > b.dot(a)) b = f;
  const double angle = std::acos(a.dot(b));
  const cv::Vec3d across = cv::normalize(b - a.dot(b) * a);
  auto at = [&](double t) { return std::cos(t) * a + std::sin(t) * across; };
  double border = 0;
  for (double t = 0; t < angle; t += 1e-4)
    if (!OnPentagon(ico, at(t))) {
      border = t;
      break;
    }
  ASSERT_GT(border, 0);
  const double deg = M_PI / 180;
  EXPECT_LT(TexelAt(texture, at(border)), 58) << "seam at the border";
  EXPECT_GT(TexelAt(texture, at(border - 2 * deg)), 60) << "pentagon inside";
  EXPECT_LT(TexelAt(texture, at(border - 2 * deg)), 100) << "pentagon inside";
  EXPECT_GT(TexelAt(texture, at(border + 2 * deg)), 200) << "hexagon outside";
}

TEST(SoccerTexture, WrapsAroundInLongitude) {
  const cv::Mat texture = SoccerTexture(256);
  cv::Mat first, last, middle;
  texture.col(0).convertTo(first, CV_64F);
  texture.col(texture.cols - 1).convertTo(last, CV_64F);
  texture.col(texture.cols / 2).convertTo(middle, CV_64F);
  // Neighbours across the seam differ only where a panel border crosses between them.
  EXPECT_LT(cv::norm(first, last, cv::NORM_L1) / first.total() / 3, 12);
  EXPECT_GT(cv::norm(first, middle, cv::NORM_L1) / first.total() / 3, 30) << "control: far columns do differ";
}

TEST(WoodTexture, SameSeedSameImageOtherSeedOtherImage) {
  const cv::Mat a = WoodTexture(128, 1), b = WoodTexture(128, 1), c = WoodTexture(128, 2);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0);
  EXPECT_GT(cv::norm(a, c, cv::NORM_L1) / a.total(), 10);
}

TEST(WoodTexture, LooksLikeBrownWood) {
  const cv::Scalar mean = cv::mean(WoodTexture(128, 3));
  EXPECT_GT(mean[2], mean[1]);  // red > green > blue: browns
  EXPECT_GT(mean[1], mean[0]);
  cv::Mat grey;
  cv::Scalar m, sd;
  cv::meanStdDev(WoodTexture(128, 3), m, sd);
  EXPECT_GT(sd[2], 8) << "rings give contrast";
}

TEST(GridBoard, SixDarkLinesEachWayAtTheExpectedPositions) {
  const int size = 400;
  const cv::Mat board = GridBoard(size);
  // Scan the middle of the first cell's row and column and find the runs of dark pixels.
  const int through = int(GridLinePositionPx(size, 0) + GridLineWidthPx(size) + 20);
  for (bool along_x : {true, false}) {
    std::vector<double> centres;
    int start = -1;
    for (int i = 0; i <= size; ++i) {
      const bool dark = i < size && (along_x ? board.at<cv::Vec4b>(through, i) : board.at<cv::Vec4b>(i, through))[1] < 128;
      if (dark && start < 0) start = i;
      if (!dark && start >= 0) {
        centres.push_back((start + i) / 2.0);
        start = -1;
      }
    }
    ASSERT_EQ(centres.size(), 6u) << (along_x ? "vertical lines" : "horizontal lines");
    const double w = size / 40.0, step = (size - w) / 5;
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(centres[k], k * step + w / 2, 1.0) << "line " << k;
  }
}

// Another count of cells: n + 1 dark lines each way, evenly spaced by (size - width) / n, each size / (8 n) wide.
TEST(GridBoard, AnyCountOfCellsHasItsLines) {
  const int size = 480;
  for (int cells : {1, 3, 8, 12}) {
    const cv::Mat board = GridBoard(size, cells);
    const double w = size / (8.0 * cells), step = (size - w) / cells;
    const int through = int(w + step / 2);  // the middle of the first cell
    std::vector<double> centres;
    int start = -1;
    for (int i = 0; i <= size; ++i) {
      const bool dark = i < size && board.at<cv::Vec4b>(through, i)[1] < 128;
      if (dark && start < 0) start = i;
      if (!dark && start >= 0) centres.push_back((start + i) / 2.0), start = -1;
    }
    ASSERT_EQ(centres.size(), size_t(cells + 1)) << cells << " cells";
    for (int k = 0; k <= cells; ++k) EXPECT_NEAR(centres[size_t(k)], k * step + w / 2, 1.0) << cells << " line " << k;
  }
  EXPECT_THROW(GridBoard(size, 0), Error);
}

TEST(GridBoard, IsAnOpaqueCard) {
  std::vector<cv::Mat> planes;
  cv::split(GridBoard(120), planes);
  double lo = 0;
  cv::minMaxLoc(planes[3], &lo);
  EXPECT_EQ(lo, 255);
}

TEST(FacePicture, TransparentCornersOpaqueCentre) {
  const cv::Mat face = FacePicture(200);
  const int w = face.cols - 1, h = face.rows - 1;
  for (const cv::Point p : {cv::Point(0, 0), cv::Point(w, 0), cv::Point(0, h), cv::Point(w, h)})
    EXPECT_EQ(face.at<cv::Vec4b>(p)[3], 0) << p;
  EXPECT_EQ(face.at<cv::Vec4b>(face.rows / 2, face.cols / 2)[3], 255);
}

TEST(FacePicture, EyesAreDarkerThanTheCheeks) {
  // Pupils sit at (+-0.3, -0.12) of the drawing's half-width, the cheeks below them.
  const cv::Mat face = FacePicture(400);
  auto grey = [&](double u, double v) {
    const cv::Vec4b p = face.at<cv::Vec4b>(int((v + 1.5) * 200), int((u + 1) * 200));
    return (p[0] + p[1] + p[2]) / 3.0;
  };
  for (double side : {-1.0, 1.0}) EXPECT_LT(grey(side * 0.29, -0.12) + 60, grey(side * 0.4, 0.3));
}

TEST(Stimuli, WriteStandardStimuliWritesFourReadablePngs) {
  const auto dir = std::filesystem::temp_directory_path() / ("blurcue_stimuli_test_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  const auto files = WriteStandardStimuli(dir);
  ASSERT_EQ(files.size(), 4u);
  const std::vector<cv::Size> sizes{{2048, 1024}, {2048, 1024}, {1024, 1024}, {800, 1200}};
  for (size_t i = 0; i < files.size(); ++i) {
    const cv::Mat image = ReadImage(files[i], cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(image.empty()) << files[i];
    EXPECT_EQ(image.size(), sizes[i]) << files[i];
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace blurcue::scene
