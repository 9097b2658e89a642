#pragma once
// Identifiability per section (issue 42). An edge within a few degrees of the pixel rows (or columns) is sampled at
// one sub-pixel phase all along it: its profile is a handful of samples across the edge, and where the blur is near
// or below a pixel those samples cannot tell a PSF's shape from its width. The same samples fit an optical blur
// (before the pixel aperture, as the lens makes it) and a sharper one filtered on the sampled image (after the
// pixel aperture, as demosaicing and sharpening do) alike, with second moments up to a factor 2 apart depending on
// where the edge lies between rows. So on such sections blur is read once per PSF family, with the edge's position
// from the pose; a filter on the sampled image is the whole photo's, so the family is chosen by all those sections
// together, whose edges lie at other phases (the one whose profiles fit them best). A section whose reading still
// depends on which of the families that fit alike is taken is flagged `phase_limited`, left out of the lens fit, and
// predicted by it.
#include <limits>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "calib/edge_blur.h"
#include "optics/fit.h"
#include "optics/thin_lens.h"

namespace blurcue::calib {

// Blur: beyond about 2 px the profile has samples enough across the edge that the families read within 2-5 % of
// each other at any phase (measured: 2.00 vs 1.90-2.16 px at r = 2); below, up to a factor 2 apart. Sections under
// it are read per family and choose one; those over it are read with the one chosen.
inline constexpr double kMaxBlurPx = 2.0;

// A PSF family: the optics (disc x Gaussian of the section's fitted shape) then, on the sampled image, a kernel at
// whole pixels on both axes: a Gaussian of std sigma_px (sharpen 0; sigma 0: the optics alone, the model the blur fit
// assumes), or an unsharp mask, (1 + sharpen) x the identity - sharpen x that Gaussian (a negative second moment).
struct PhaseFamily {
  double sigma_px = 0, sharpen = 0;
  bool fitted = false;  // not one of PhaseFamilies(): refined between them (phase_fit.h)
  std::string Name() const;  // "the optics alone", "the optics then a Gaussian of std 0.45 px on the sampled image"
};

// What one family reads on a section.
struct PhaseReading {
  double r_px = 0;       // 2 x the std of the whole line spread: sqrt(r_optics^2 + 4 x the kernel's second moment)
  double offset_px = 0;  // where it puts the edge, from the pose's line (within 0.15 px of it)
  double rms_rel = 0;    // its residual rms / |step|
  double chi2 = 0;       // its residual sum of squares over the noise variance (PhaseCheck::noise)
  // On a board's outer edge, where the table's texture may slope across the window: r_px read with that slope as one
  // more linear term (NaN elsewhere). ChoosePhaseFamily flags a section whose two readings differ by the target.
  double r_table_px = std::numeric_limits<double>::quiet_NaN();
  // r_px's standard error (the section's noise through the fit; ReadingSe), NaN where not taken (the refinement
  // between families), infinite where the profile does not bound it.
  double r_se_px = std::numeric_limits<double>::quiet_NaN();
};

struct PhaseCheck {
  // Few phases and blur near or below a pixel: the readings below were taken (otherwise empty).
  bool limited = false;
  // Every phase and blur under 2 px: the families were read too (ReadPhaseFamilies, not CheckPhase). Such a section
  // tells the families apart on its own and joins the choice; where a filter after sampling is chosen it is read with
  // it (a board turned a few degrees under a filter: read as the optics alone, 28 sections were off the rule).
  bool every_phase = false;
  // Blur of 2 px or more (neither of the above): where a filter after sampling fits the others best, read with the
  // families read on them (ReadPhaseFamilies) and then with the chosen one (ChoosePhaseFamily), not with the optics
  // alone: under a mask the blur fit's disc x Gaussian reads about the optics' blur without the mask's negative second
  // moment (turned 60 deg, amount 0.7 over 0.6 px: edge 1 section 1 at 2.54 px for a true 2.26 px, the optics 2.47 px).
  bool wide = false;
  double axis_deg = 0;  // the edge's angle to the nearest pixel axis
  double span_px = 0;   // how far its sub-pixel phase moves along the part measured (1 px or more: every phase)
  double phase_px = 0;  // where the edge (from the pose) lies between pixel centres at its midpoint, 0..1
  double noise = 0;     // the pixels' noise std about the profile (linear light), from the spread within its bins
  int bins = 0;         // profile points the families were fitted to
  // One per PhaseFamilies(), in that order; a family ReadPhaseFamilies ruled out before reading it here has r_px NaN
  // and chi2 infinity.
  std::vector<PhaseReading> families;
  // Set by ChoosePhaseFamily: the readings of the families that fit the photo's profiles alike span this (px).
  double range_lo_px = 0, range_hi_px = 0;
  // Flagged only because the chosen sharpening cancels most of the optics' blur here (the families that fit alike
  // agree, and the reading follows its neighbouring families): the reading is the chosen family's, unsure alone by
  // how much the mask amplifies an error in it, not by which family reads it. Such a section joins the lens fit at its
  // reading (ModelSamples), which pools many of them; the other phase_limited sections stay out and hold it to their
  // ranges (FitModelWithinPhaseRanges). Without them nothing near focus pins the floor: on a mask of amount 0.7 the
  // model read 0.19 px for a true 0.16 px, p90 19-29 % over 6 scenes.
  // Flagged for its standard error alone (FlagUnsureAtItsPhase: an edge near a pixel centre under a pixel of blur)
  // joins it too: its reading is unbiased but noisy, and pooled it pins the model near focus.
  bool joins_fit = false;
  // Its reading under a sharpening family is under kCancelledPx: the mask cancels the optics' whole second moment
  // there, so the reading is a bound (the optics' blur at most the mask's), not a value: it does not join the lens fit
  // at it, and its range (0 to what kOpticsRel of the optics' blur leaves) holds the model instead.
  bool bound = false;
  // Read with the families at either end of the chosen mask's valley (PhaseChoice::valley), NaN where not read.
  double valley_r_px[2] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
};

// The families read (the optics alone first).
const std::vector<PhaseFamily>& PhaseFamilies();

// The families next to family c along its own axis (a Gaussian's std, an unsharp mask's amount at its std; the optics
// alone is the zero of each), indices into PhaseFamilies(): ChoosePhaseFamily's jump test reads a section with them.
std::vector<size_t> PhaseNeighbours(size_t c);

// Reads a section's blur once per family where its phases are few and its blur (`fit`, the blur fit's own reading)
// is below about 2 px; `linear` as for MeasureEdgeModel. The edge lies where the pose puts it (the segment line).
PhaseCheck CheckPhase(const cv::Mat& linear, const EdgeSegment& segment, const ModelFit& fit,
                      const ModelFitOptions& options = {});

struct CalibResult;
// CheckPhase on every usable section of `result` (on every core when `parallel`), reading no more than the photo
// needs: where more than 24 sections are limited, every family is read on 12 of them at phases spread over the pixel,
// and on the others only the families that fit those 12 within twice ChoosePhaseFamily's "alike" margin of the best
// (and the optics alone). Where that best is a filter, it is refined between the families on those 12 (all, with 24
// or fewer; RefinePhaseFamily) and read on every limited section as one more family (result.phase.families). The
// choice and the flags are ChoosePhaseFamily's, over every limited section.
void ReadPhaseFamilies(CalibResult& result, const cv::Mat& linear, const ModelFitOptions& options, bool parallel);

// What the sections at other phases chose (calib.json's phase_check).
struct PhaseChoice {
  int limited = 0;               // usable sections whose phases are few (PhaseCheck::limited)
  int every_phase = 0;           // usable sections at every phase with blur under 2 px (PhaseCheck::every_phase)
  int flagged = 0;               // of those, flagged phase_limited
  int held = 0;                  // of those, sections whose range held the lens model (FitModelWithinPhaseRanges)
  // The families read on this photo: PhaseFamilies() and, where one of its filters fitted the sections at spread
  // phases best, that filter refined between them (RefinePhaseFamily) last. Empty: PhaseFamilies().
  std::vector<PhaseFamily> families;
  size_t chosen = 0;             // the family chosen (in `families`; 0: the optics alone)
  size_t choice_sections = 0;    // sections every family was read on before others were ruled out (0: every one)
  // Per family: chi-square of its profiles over every limited section (the filter is the whole photo's), each section's
  // in units of its own misfit (WeighedTotals in phase_check.cc), and whether it fits
  // them alike with the chosen one (within 25 after scaling by the best's chi-square per point, or 15 % of it).
  std::vector<double> chi2;
  std::vector<bool> alike;
  double chi2_per_point = 0;     // the chosen family's: about 1 where it describes the profiles to the noise
  // Where a mask was refined between the families: the masks either side along its valley of one second moment that
  // the deciding sections' profiles cannot tell from it (ValleyEnds), read on every section it reads (valley_r_px).
  // The readings move alike along it (a mask of 0.25 over 0.9 px read as 0.24 over 0.95 px: every edge 2-5 % low),
  // which no scatter about the lens model shows: PropagateModelError adds the models refitted under them.
  bool has_valley = false;
  PhaseFamily valley[2];
  // The chosen family's taps' second moment across a level edge (px^2; negative for a mask, 0 for the optics alone):
  // a section reads sqrt(r_optics^2 + 4 variance_px2) (FitModelWithinPhaseRanges fits a mask's photo in r_optics).
  double variance_px2 = 0;
  std::string summary = "not checked (--no-phase-check, or a take's frames: no lens fit per frame)";  // in words
  // With no section under 2 px (nothing to choose a family on): where a sharpening after sampling fits the wide
  // sections' profiles better than the lens alone (WeighedTotals's test on up to 12 of them), its name, both
  // chi-squares and how far it moves their readings; calibrate refuses such a photo where that is over
  // kMaxWideSharpeningMove (calib_checks.h): the readings are the lens's and the mask's together there, and nothing in
  // the photo pins the mask (the families' grid stops at a mask of 0.7 over 1 px, so the move is a lower bound).
  struct Wide {
    std::string sharpening;  // empty: none fits better
    double chi2_optics = 0, chi2_sharpening = 0;
    int sections = 0;
    double moved_rel = 0;  // the median of |its reading - the lens's alone| / the lens's alone over those sections
  } wide;
};

// Chooses the family over `result`'s limited sections (the one whose profiles fit best over all of them: sections at
// other phases tell the families apart where one cannot), reads them with it, and flags `phase_limited` (ok = false,
// with ModelFit::phase_why) those whose readings differ by more than max(0.04 px, 8 %) among the families that fit
// alike.
PhaseChoice ChoosePhaseFamily(CalibResult& result);

// The thin-lens model fitted to the usable sections and those that join it (ModelSamples) and held to the range each
// other phase_limited section leaves open: where it predicts such a section outside [range_lo_px, range_hi_px], the range's middle joins the
// samples and the model is fitted again (a few rounds). A section whose range holds the prediction stays out. Without
// them the sections near focus, where the blur is sub-pixel, could all be gone and nothing would pin the floor.
// Where the chosen family sharpens (PhaseChoice::variance_px2 < 0) the model is fitted to the optics' readings,
// sqrt(r^2 - 4 variance_px2), and returned with the filter added back to its floor: near focus the mask magnifies an
// error in the optics' reading by r_optics / r, and in the optics' terms the floor is the lens's.
// `optics_model`, where given, receives the model as fitted (of the optics alone where the family sharpens).
optics::FittedModel FitModelWithinPhaseRanges(const CalibResult& result, const optics::Lens& lens,
                                              const optics::FitOptions& options, int* held = nullptr,
                                              optics::FittedModel* optics_model = nullptr);

// On every photo with a lens fit: the lens model's standard error at every section (SectionResult::r_fitted_se_px)
// and the depths where it exceeds 5 % (CalibResult::undetermined), propagated from `optics_model`'s fit to the
// optics' readings (FitModelWithinPhaseRanges) with the sections of one edge as one sample (they share its phase),
// the readings' own error in the optics' blur added (larger where the filter cancels the whole blur on an edge).
// `valley`: the optics' models refitted with the readings under PhaseChoice::valley's masks (ValleyModels), each
// with its mask's variance: half their largest difference from the model's blur is added to its standard error.
struct ValleyModel {
  optics::FittedModel optics;
  double variance_px2 = 0;
};
std::vector<ValleyModel> ValleyModels(const CalibResult& result, const optics::Lens& lens,
                                      const optics::FitOptions& options);
void PropagateModelError(CalibResult& result, const optics::Lens& lens, const optics::FittedModel& optics_model,
                         const std::vector<ValleyModel>& valley = {});

}  // namespace blurcue::calib
