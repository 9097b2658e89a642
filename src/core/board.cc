#include "core/board.h"

#include <cmath>
#include <string>

#include "core/error.h"
#include "core/typed.h"

namespace blurcue {

void Board::Validate(const std::string& where) const {
  // Compared one by one first: cols * rows of two huge values would overflow.
  if (cols < 2 || rows < 2 || cols > kMaxSquares || rows > kMaxSquares || cols * rows < 6)
    throw InputError(where, "a board needs 2 to " + std::to_string(kMaxSquares) +
                                " squares a side and at least 2 x 3 squares, got " + Name());
  if (cols == rows) throw InputError(where, "a square board (" + Name() + ") has no unique orientation");
  if (!(square_mm > 0) || !std::isfinite(square_mm))
    throw InputError(where, "square size must be > 0 mm, got " + std::to_string(square_mm));
}

Board Board::Parse(const std::string& text, double square_mm) {
  // Digits only, at most three a side (sscanf's %d would wrap 4294967303 to 7 without a word).
  const size_t x = text.find_first_of("xX");
  auto side = [&](size_t from, size_t to) {
    const std::string digits = text.substr(from, to - from);
    if (digits.empty() || digits.size() > 3 || digits.find_first_not_of("0123456789") != std::string::npos) return -1;
    return std::stoi(digits);
  };
  Board b;
  b.cols = x == std::string::npos ? -1 : side(0, x);
  b.rows = x == std::string::npos ? -1 : side(x + 1, text.size());
  if (b.cols < 0 || b.rows < 0)
    throw Error(ErrorKind::kUsage, "--board: expected COLSxROWS in squares such as 7x10, got " + Echo(text));
  b.square_mm = square_mm;
  try {
    b.Validate("--board " + text);
  } catch (const Error& e) {
    throw Error(ErrorKind::kUsage, e.what());  // a command-line value: exit 2, as for every option
  }
  return b;
}

}  // namespace blurcue
