#pragma once
// Two of the phase check's rules on a section, and the lens fit held to the flagged sections' ranges
// (phase_check.h's FitModelWithinPhaseRanges): what ChoosePhaseFamily does with a section once the family is chosen.
#include "calib/calibrate.h"

namespace blurcue::calib {

// With the optics alone, a section at few phases whose reading's standard error (ModelFit::r_se_px) exceeds
// kMaxRelSe of it is flagged phase_limited and joins the lens fit at its reading (PhaseCheck::joins_fit). True when
// it flagged the section.
bool FlagUnsureAtItsPhase(SectionResult* s);

// Where a filter after sampling was chosen: an unflagged limited section off the line (r against depth) through its
// edge's other such sections by more than max(kEdgeLinePx, kEdgeLineRel) is flagged. Returns how many.
int FlagOffTheirEdge(CalibResult& result);

}  // namespace blurcue::calib
