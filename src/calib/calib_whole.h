#pragma once
// A calibration's fields checked against each other (internal to calib: SceneCalibFromJson calls it). Each field may
// be in its range and the whole still be no calibration calibrate wrote: a board of 8 columns whose edges list 7
// sections, a section's depth or image position edited by hand. Every refusal names the file and the field.
#include <string>

#include "calib/scene_blur.h"
#include "core/json_io.h"

namespace blurcue::calib {

// Throws Error(kInput) "FILE: /pointer: what, got what" unless `j`, read into `s` field by field, is whole:
//   - the edges listed are the board's rows + 1, each with the board's columns of sections (calibrate writes every
//     edge and every section, usable or not);
//   - r_units is what calibrate writes for the camera (the photo's px without dist_coeffs, photo and ideal px with);
//   - every depth u_mm (an edge's, a section's) is positive and finite, and a section's is its midpoint's depth;
//   - every section's image_px is two finite points, both inside the image when the section is usable (measured).
// `where` is "FILE: ".
void RequireWholeCalib(const Json& j, const SceneCalib& s, const std::string& where);

}  // namespace blurcue::calib
