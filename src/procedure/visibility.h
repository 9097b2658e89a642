#pragma once
// What a participant can see of a protocol before anyone sits down: for every distinct stimulus pair, on the session's
// display, the probability that an observer (the simulated observer's model, without lapses or bias) tells its two
// sides apart in a 2AFC - and the pairs below a stated level flagged. `blurcue validate --plan` and `blurcue preview`
// print it; both start from PrepareSession, as `blurcue run` does.
#include <string>
#include <vector>

#include "protocol/trials.h"
#include "procedure/observer.h"
#include "procedure/prepare.h"

namespace blurcue::procedure {

struct PairVisibility {
  std::string what;        // "measured vs estimated at edge 2", or "object measured vs the scene at blur 3"
  double r_a_arcmin = 0, r_b_arcmin = 0;  // the two radii compared on the screen (left, right; or object, scene)
  double p_correct = 0.5;  // ProbabilityCorrect2afc of the two
  bool visible = false;    // p_correct >= the level asked for
  int trials = 0;          // trials of the list showing this pair (either side order)
  // One object against the scene's blur (a single layout): below the level it looks as blurred as the scene - what a
  // study of whether objects belong asks, so it is said so, not flagged as a pair no one could tell apart.
  bool against_scene = false;
};

// A trial's levels as a label: "edge 2", "edge 2 speed 3", an object level by its id or its members
// ("comparison left=measured;right=estimated edge 3"); "" without levels.
std::string LevelsLabel(const protocol::Trial& trial);

// Every distinct pair of the prepared session's trial list (the same levels and sources, either side order, counted
// once), each trial of a procedure at its first level (ApplyLevel, as `blurcue preview` shows it): its two radii on the
// presentation, in arcmin, and the observer's probability of telling them apart. A layout-single trial (one object)
// compares its object with the scene's own blur there. Adjustment (picture) trials have no pair: none are listed.
// `level`: the share correct below which a pair is not visible.
std::vector<PairVisibility> PairVisibilities(const PreparedSession& prepared, const ObserverParams& observer,
                                             double level);

// Depth matching (adjustment trials of a picture whose real photos' camera is known, content.real_camera): per
// distance, the real picture's blur and which of the levels the observer cannot tell from it - the levels whose
// 2AFC share correct against the real blur is below `level`. Many such levels at a distance mean the match there
// cannot say which of them was meant. Empty for other protocols, or without real_camera; model=pixel has no arcmin
// and throws Error(kUsage).
struct MatchVisibility {
  double distance_m = 0, r_real_arcmin = 0;
  int levels = 0;                        // distinct levels offered
  std::vector<double> alike;             // the levels (cut-offs) that look like the real picture, ascending
  double alike_r_min = 0, alike_r_max = 0;  // their blurs (arcmin, blurcue's r)
  double closest = 0, closest_r_arcmin = 0, closest_p = 0.5;  // the level nearest in seen blur, and its share correct
  int trials = 0;
};
std::vector<MatchVisibility> MatchVisibilities(const PreparedSession& prepared, const ObserverParams& observer,
                                               double level);
// "depth matching at 1 m: the real picture's blur 0.00' - 9 of 22 levels look the same (under 75 % correct):
// cut-offs 16.5-80 (0.53'-2.59'); the closest, 80 (1.07'), 51 % correct"
std::string Describe(const MatchVisibility& match, double level);

// What `blurcue validate --plan` and `blurcue preview` print of it: a header naming the observer, the level and the
// counts, then every pair (or with `invisible_only` only the invisible ones) and every distance of a depth matching
// (model=arcmin; model=pixel has no visual angle for it and says so).
std::vector<std::string> VisibilityLines(const PreparedSession& prepared, const ObserverParams& observer, double level,
                                         bool invisible_only);

// "measured vs estimated at edge 2: 0.30 arcmin apart (0.50' vs 0.80'), predicted 53 % correct - invisible at 60 cm on
// this monitor" (the profile's distance), or "... predicted 91 % correct".
std::string Describe(const PairVisibility& pair, const display::Profile& profile);

}  // namespace blurcue::procedure
