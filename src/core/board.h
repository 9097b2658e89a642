#pragma once
// The printed checkerboard and the board frame every module shares.
//
// Board frame (mm): origin at the outer corner of the first square of the near row; x along the row of `cols`
// squares (left to right as the camera sees it), y along the `rows` direction away from the camera, z = x cross y
// (up, out of the table). Edge k (1-based, 1 = nearest) is the line y = (k - 1) * square_mm; section j (1-based)
// of an edge spans x in [(j - 1) * square_mm, j * square_mm]. A 7 x 10 board thus has 11 edges x 7 sections.
// The square at column 0, row 0 is black; colours alternate.
#include <array>
#include <string>

namespace blurcue {

struct Board {
  int cols = 7;
  int rows = 10;
  double square_mm = 25;

  int EdgeCount() const { return rows + 1; }
  int SectionCount() const { return cols; }
  int InnerCornersX() const { return cols - 1; }
  int InnerCornersY() const { return rows - 1; }
  double WidthMm() const { return cols * square_mm; }
  double LengthMm() const { return rows * square_mm; }
  // Midpoint of section `section` on edge `edge` (both 1-based), board frame, z = 0.
  std::array<double, 3> SectionMidpoint(int edge, int section) const {
    return {(section - 0.5) * square_mm, (edge - 1) * square_mm, 0.0};
  }
  // End points of that section (x = (section-1)*s and section*s on the edge's line).
  std::array<double, 3> SectionStart(int edge, int section) const {
    return {(section - 1) * square_mm, (edge - 1) * square_mm, 0.0};
  }
  std::array<double, 3> SectionEnd(int edge, int section) const {
    return {section * square_mm, (edge - 1) * square_mm, 0.0};
  }
  bool IsBlack(int col, int row) const { return (col + row) % 2 == 0; }

  static constexpr int kMaxSquares = 100;  // a side; the study's board is 7 x 10
  // Throws Error(kInput) naming `where` for fewer than 2 x 3 squares or more than kMaxSquares a side, a square
  // board (pose would be ambiguous) or square_mm <= 0.
  void Validate(const std::string& where) const;
  // Parses "7x10" (cols x rows, in squares); throws Error(kUsage) naming the text.
  static Board Parse(const std::string& cols_x_rows, double square_mm);
  std::string Name() const { return std::to_string(cols) + "x" + std::to_string(rows); }
};

}  // namespace blurcue
