#pragma once
// The study's stimulus textures, drawn procedurally (no downloaded images) and deterministically, as 8-bit sRGB.
// Spherical textures are equirectangular in the convention of the ball in render/scene_render.cc: texel (x, y) of a
// W x H image (W = 2H) looks along theta = pi (y + 0.5) / H from +z, phi = 2 pi (x + 0.5) / W from +x towards +y.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace blurcue::scene {

// A stimulus by name or path: an existing file as given, else the shipped stimuli/NAME.png (soccer, wood, grid,
// face). Throws Error(kInput) naming both places when neither exists.
std::filesystem::path ResolveStimulus(const std::string& name_or_path);

// The unit direction a texel centre (x, y) of an equirectangular image of width_px x width_px / 2 looks along.
cv::Vec3d EquirectDirection(double x, double y, int width_px);

// A classic soccer ball: 12 near-black pentagons, 20 warm-white hexagons, dark-grey seams seam_width_deg wide
// (0: none). Panels are the faces of a truncated icosahedron projected from its centre: a direction belongs to the
// face whose plane it meets first. Pose: a pentagon centred on each pole, the five upper pentagons around the
// +z one centred at longitudes 0, 72, ..., 288 deg. 8-bit sRGB BGR, width_px x width_px / 2, anti-aliased
// (3 x 3 samples near borders); width_px must be even and >= 16.
cv::Mat SoccerTexture(int width_px, double seam_width_deg = 1.6);

// Wood grain for a ball carved from a log: rings around a slightly wavy axis, smooth noise, browns. Same seed,
// same image. 8-bit sRGB BGR, width_px x width_px / 2; width_px must be even and >= 16.
cv::Mat WoodTexture(int width_px, uint64_t seed);

// User test 1's 5 x 5 grid board, or one of `cells` x `cells`: a white square card, black lines (outer border
// included, width size_px / (8 cells)) bounding equal cells. 8-bit sRGB BGRA, opaque; size_px >= 8 cells.
cv::Mat GridBoard(int size_px, int cells = 5);

// Where line i (0..cells) of a GridBoard(size_px, cells) starts, in pixels from the card's edge (width
// GridLineWidthPx).
double GridLinePositionPx(int size_px, int i, int cells = 5);
double GridLineWidthPx(int size_px, int cells = 5);

// The depth-matching study's face-like picture (8 x 12 cm in the study): a drawn, softly shaded face with hair;
// transparent outside the head. 8-bit sRGB BGRA, width_px x 1.5 width_px; width_px must be even and >= 16.
cv::Mat FacePicture(int width_px);

// Writes soccer.png (2048 x 1024), wood.png (2048 x 1024, seed 1), grid.png (1024 x 1024) and face.png
// (800 x 1200) into dir (created if needed); returns the files written. Throws Error naming a file on failure.
std::vector<std::filesystem::path> WriteStandardStimuli(const std::filesystem::path& dir);

}  // namespace blurcue::scene
