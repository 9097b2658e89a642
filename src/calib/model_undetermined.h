// Where the lens model's blur is not determined within 5 % (calibrate's PropagateModelError: its standard error, the
// readings' own and, under a mask, the masks that fit alike), as calibrate found it and calib.json's
// model.undetermined holds it: camera depths (mm), the largest relative standard error on the board, and why.
#pragma once

#include <cstdio>
#include <string>

namespace blurcue::calib {

struct ModelUndetermined {
  double lo_mm = 0, hi_mm = 0, worst_se_rel = 0;
  std::string why;  // the sentence calibrate prints (empty: nowhere on the board)
  bool Named() const { return hi_mm > 0; }
  bool Inside(double u_mm) const { return Named() && u_mm >= lo_mm && u_mm <= hi_mm; }
  // The largest error in words: "23 %", or where the blur there is near 0 (its error no percentage of it; one scene
  // read 3439 %) "more than the blur itself".
  std::string Reach() const {
    if (worst_se_rel > 1) return "more than the blur itself";
    char text[48];
    std::snprintf(text, sizeof text, "%.0f %%", 100 * worst_se_rel);
    return text;
  }
};

}  // namespace blurcue::calib
