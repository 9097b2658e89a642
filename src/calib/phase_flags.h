#pragma once
// Two of the phase check's rules on a section, and the lens fit held to the flagged sections' ranges
// (phase_check.h's FitModelWithinPhaseRanges): what ChoosePhaseFamily does with a section once the family is chosen.
#include "calib/calibrate.h"

#include <array>
#include <string>

namespace blurcue::calib {

// A reading that moves by more than this among the families that fit alike is not identified (the target
// is max(0.05 px, 10 %): a reading within the alike families' spread of a family that holds meets it with margin).
inline constexpr double kSpreadPx = 0.04, kSpreadRel = 0.08;
// The optics' own reading is good to about this (relative; the physical scenes' median error is 0.5-1.1 %, p90
// 1.5-3.3 %): where a sharpening mask cancels most of it, the section's reading is flagged when an error this size moves
// it past the spread above (CancellationPx). Readings under kOpticsFloorPx count as that (the error is not relative).
inline constexpr double kOpticsRel = 0.02, kOpticsFloorPx = 0.05;
// A reading under this (px) where the chosen family sharpens reads the mask cancelling the optics' whole second moment:
// its profile reads 0, and its optics' reading sqrt(-4 v) is a bound, not a value (the tests' scale for a blur near 0).
inline constexpr double kCancelledPx = 0.05;
// A section at every phase under a chosen filter whose reading's standard error (PhaseReading::r_se_px) times this
// exceeds the spread above is flagged (FlagNoisyAtEveryPhase): the reading is not pinned within the target. 2: on 16
// boards turned 45-60 deg under a mask (amount 0.7 over 0.6 px; seeds 2, 9, 11-16) the five sections off the rule
// unflagged, all on the board's outer edges, had standard errors of 4.5-9.4 % (two of them 1.14 x the spread's 8 %);
// 24 of the 122 other outer-edge sections measured were flagged with them, none of the 433 inner ones (1.8: 19;
// 2.5: 44 and 2 inner).
inline constexpr double kSeSpan = 2;

// A section joined to the fit by the cancellation alone whose reading r under a sharpening of variance v < 0 is under
// kCancelledPx: a bound (PhaseCheck::bound), no longer joined; its range holds the model instead. Joined at it, as a
// value, 28 such sections of a scene focused in front of the board (mask 0.7 over 0.8 px, focus 330 mm) put the fit's
// focus at 375 mm and its blur 24 % high on the next edge. True when it made the section a bound.
bool HoldAsBound(SectionResult* s, double r, double v);

// Why a section on the board's outer edge is flagged where its reading moves with the table's slope, in words.
std::string TableWhy(double r, double r_table);
// A flagged section's reason, in words (calib.json's phase_why and the summary): the families alike read lo-hi, the
// chosen one r under a filter of variance v, `moved` by the cancellation, `nearest` its nearest neighbouring family's.
std::string PhaseWhy(const SectionResult& s, double lo, double hi, double r, double v, double moved, double nearest);
// A section flagged where the masks at the ends of the chosen mask's valley (PhaseChoice::valley) read lo-hi about its r.
std::string ValleyWhy(double r, double lo, double hi);
// ChoosePhaseFamily's summary: `flags` counts the flags by reason (cancelled, jumped, off their edge, unsure, moved by
// the table's slope, noisy at every phase, read apart by the families that fit alike, read apart along the valley);
// `wide` the sections of 2 px or more read with the chosen family.
std::string ChoiceSummary(const PhaseChoice& choice, size_t best, const std::array<int, 8>& flags, int wide);

// Where a filter after sampling was chosen (family `best`), a section at every phase that no other rule flagged and
// whose reading's standard error times kSeSpan exceeds `target` is flagged phase_limited and joins the lens fit at its
// reading (as FlagUnsureAtItsPhase's). On a board's outer edge the profile's noise takes in the table's texture (a
// 0.1 px bin of such a section holds pixels from a few places along the edge): turned 45-60 deg under a mask, the
// outer edges' standard errors were 3 x the inner edges' and five of their sections read 10-14 % high unflagged.
// True when it flagged the section.
bool FlagNoisyAtEveryPhase(SectionResult* s, size_t best, double target);

// With the optics alone, a section at few phases whose reading's standard error (ModelFit::r_se_px) exceeds
// kMaxRelSe of it is flagged phase_limited and joins the lens fit at its reading (PhaseCheck::joins_fit). True when
// it flagged the section.
bool FlagUnsureAtItsPhase(SectionResult* s);

// Where a filter after sampling was chosen: an unflagged limited section off the line (r against depth) through its
// edge's other such sections by more than max(kEdgeLinePx, kEdgeLineRel) is flagged. Returns how many.
int FlagOffTheirEdge(CalibResult& result);

// Where a filter after sampling was chosen (result.phase.chosen != 0), after the lens fit (ApplyModel, and
// PropagateModelError where it sharpens): a measured section on the board's outer edge (edge 1 or the last, the
// table beside it) whose reading lies off the fit's prediction by more than max(kSpreadPx, kSpreadRel) of it less the
// prediction's standard error (r_fitted_se_px; 0 where none was propagated) is flagged phase_limited and joins the
// fit at its reading, which the fit held already (the model unchanged). The table's texture there moves a reading
// more than its standard error says: over 200 scenes (10 kinds of filter and turn, seeds 1-10 and 17-26) 5 outer-edge
// sections read 10-15 % high unflagged at 2.8-4.1 standard errors, none of the inner ones; this flags all 5 and 66 of
// the 2656 outer-edge sections measured. Counts them in result.phase (flagged, and a clause of its summary); returns
// how many it flagged.
int FlagOffTheLensFit(CalibResult& result);

}  // namespace blurcue::calib
