#pragma once
// The post filter between the PSF families (issue 42): a camera's demosaicing or sharpening is never exactly one of
// PhaseFamilies(), and where the mask cancels most of the optics' blur a family a grid step away reads sections near
// focus 10-15 % off while fitting the board's profiles nearly as well (an unsharp mask of amount 0.25, std 0.9 px read
// as 0.3 at 0.8 px: edge 4 at 0.61 px for 0.55 px). The family that fits best is refined continuously along its own
// parameters (a Gaussian's std; an unsharp mask's std and amount) by the profiles of the sections at spread phases.
#include <array>
#include <functional>

#include "calib/phase_check.h"

namespace blurcue::calib {

// From `start` (a Gaussian or an unsharp mask of PhaseFamilies(); the optics alone is returned as it is), the family
// of the same kind whose `chi2` (the profiles' chi-square under it, summed over the sections that choose) is least,
// found by a Nelder-Mead search of at most `evaluations` calls, within sigma 0.3-1.6 px and amount 0.02-1.5. The
// result has `fitted` set; it is `start` (fitted) where no step improved on it.
PhaseFamily RefinePhaseFamily(const PhaseFamily& start, const std::function<double(const PhaseFamily&)>& chi2,
                              int evaluations = 30);

// Along the valley of one second moment through `found` (a mask: its std moved by 0.02 px steps, its amount keeping
// amount x its Gaussian's taps' variance), the first std either side whose `chi2` exceeds chi2(found) + margin (at
// most 0.3 px away, within the search's range): the masks the profiles do not tell from `found`.
std::array<PhaseFamily, 2> ValleyEnds(const PhaseFamily& found, const std::function<double(const PhaseFamily&)>& chi2,
                                      double margin);

}  // namespace blurcue::calib
