#pragma once
// The session's one door to the record (store): what a session records, in session terms.
#include "core/json_io.h"
#include "protocol/trials.h"
#include "stimulus/stimulus.h"

namespace blurcue::session {

// The variables recorded with a trial beside its factor levels: practice, block_name, swapped, and for pairs each
// radius in photo px, screen px and arcmin (r_left_px, r_left_screen_px, r_left_arcmin; the same for right and
// scene) with the presentation's screen_px_per_photo_px and the blur plan (blur_plan: one_radius | per_pixel,
// r_span_screen_px) and each object's size_left_deg / size_right_deg, or start_level and adjust_levels (adjustment;
// a picture: picture_width_arcmin, and the real picture's r_scene_* when content.real_camera names its camera).
// Each level is recorded under store::DesignColumn(name): factor_NAME for one named like any of those or like a
// column of trials.csv (store::IsRecordedName), so nothing recorded takes a level's place.
Json TrialVariables(const protocol::Trial& trial, const stimulus::TrialScene& scene, const stimulus::Presentation& presentation);

}  // namespace blurcue::session
