#include "core/board.h"

#include <cmath>
#include <cstdio>

#include "core/error.h"

namespace blurcue {

void Board::Validate(const std::string& where) const {
  if (cols < 2 || rows < 2 || cols * rows < 6)
    throw InputError(where, "a board needs at least 2 x 3 squares, got " + Name());
  if (cols == rows) throw InputError(where, "a square board (" + Name() + ") has no unique orientation");
  if (!(square_mm > 0) || !std::isfinite(square_mm))
    throw InputError(where, "square size must be > 0 mm, got " + std::to_string(square_mm));
}

Board Board::Parse(const std::string& text, double square_mm) {
  Board b;
  char x = 0;
  char extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &b.cols, &x, &b.rows, &extra) != 3 || (x != 'x' && x != 'X'))
    throw Error(ErrorKind::kUsage, "--board: expected COLSxROWS in squares such as 7x10, got '" + text + "'");
  b.square_mm = square_mm;
  b.Validate("--board " + text);
  return b;
}

}  // namespace blurcue
