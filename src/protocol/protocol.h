#pragma once
// A study protocol: a JSON file (format in protocols/protocol.schema.json) parsed into a validated `Protocol`.
// Validation reports every problem at once, each as "FILE: /json/pointer: what is wrong, got VALUE", so one run of
// `blurcue validate` shows all typos, wrong types, missing fields, impossible values and missing files.
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/json_io.h"
#include "protocol/level.h"
#include "protocol/vocabulary.h"

namespace blurcue::protocol {

// One factor: its name and its levels (numbers, strings or objects of them, typed) in the order the file lists them.
struct Factor {
  std::string name;
  std::vector<Level> levels;  // each Level::factor is `name`
};

// Method of adjustment: the participant steps through `levels` of `parameter` and accepts one.
struct Adjustment {
  std::string parameter = "cutoff";   // what the levels set, e.g. the Butterworth cut-off (cycles per picture width)
  std::vector<double> levels;
  AdjustOrder order = AdjustOrder::kShuffled;  // shuffled: a fresh random order per trial
};

// An adaptive procedure (a block's "procedure"): the stimulus of each trial is decided from the answers so far.
// Both sides show `reference`; on the test side (left or right at random, seeded) the procedure's level adds blur -
// "relative_difference": the test radius is (1 + level) x the reference's (a blur gain of 1 + level);
// "difference_arcmin": the test radius on screen is the reference's plus level arcmin. Level 0 is no difference. The participant says which side is more blurred; choosing the test side is
// correct (can't tell is not). Each crossing of the block's factors runs its own procedure for `trials` trials, all
// interleaved in the block's shuffled order (like PsychoPy's MultiStairHandler).
struct Procedure {
  using Kind = ProcedureKind;
  Kind kind = Kind::kStaircase;
  ProcedureVariable variable = ProcedureVariable::kRelativeDifference;
  BlurSpec reference;                // the blur source both sides start from
  int trials = 30;                   // per crossing of the block's factors
  // Staircase: n-up/m-down (down correct answers in a row step the level down, up wrong ones step it up); the step
  // is steps[k] after k reversals (the last one kept); the level stays in [min, max].
  double start = 1, min = 0, max = 1;
  int up = 1, down = 2;
  std::vector<double> steps;
  int stop_reversals = 0;            // "stop": {"reversals": n}: ends after n reversals (0: runs all its trials)
  // QUEST+ (Watson 2017) with the Weibull p = 1 - lapse - (1 - guess - lapse) exp(-(x / threshold)^slope): the
  // stimulus of least expected posterior entropy among `stimuli`, over a uniform prior on the parameter grid.
  std::vector<double> stimuli, thresholds, slopes, lapses;
  double guess = 0.5;
  bool guess_given = false;          // the file gave guess (else it is chance: 0.5, or 1/n for an odd one out)
};

// The most trials a session may have, practice included: at ~2 s a trial, more than five hours. Checked (with
// overflow-safe arithmetic) before a trial list is made, so no design can exhaust memory or wrap a count.
inline constexpr int kMaxTrials = 10000;

// When things happen in a trial (the protocol's "timing", or a block's overriding it field by field).
struct Timing {
  double stimulus_ms = 0;             // 0: until the participant answers
  double inter_trial_ms = 500;
  double interval_ms = 1000, isi_ms = 500;  // layout two_intervals: each interval, and the grey between them
  double deadline_ms = 0;             // forced choice: no answer this long after onset records "none"; 0: no deadline
  double feedback_ms = 0;             // procedure trials: "Correct" / "Wrong" / "Too slow" shown this long; 0: none
  double fixation_ms = 0;             // a fixation mark (+) on grey before each stimulus; 0: none
};

// A block of trials with its own design; blocks run in file order, trials are randomised within a block.
struct Block {
  std::string name;
  // JSON pointers of where the block's fields were read ("" is the top level for an inherited field), so a
  // problem found later (a source that cannot be evaluated) names the field that asked for it.
  std::string pointer, task_pointer, factors_pointer, sides_pointer, counterbalance_pointer;
  Task task = Task::kForcedChoice;
  std::vector<Factor> factors;        // crossed in full; sorted by name (JSON object order)
  std::string conditions;             // a conditions table's path as the protocol writes it (its factor "row"); "" for none
  int repetitions = 1;
  Counterbalance counterbalance = Counterbalance::kNone;
  // "sides": what each side shows when no factor's levels carry the sides: {left: SOURCE, right: SOURCE}, or the
  // single layout's {"object": SOURCE} (shown as the left side and recorded on both). A source the parser refused is
  // left unset.
  struct Sides {
    bool object = false;
    std::optional<BlurSpec> left, right;
  };
  std::optional<Sides> sides;         // set when the block (or the protocol) gives a "sides" object
  std::optional<Adjustment> adjust;   // set for the adjustment task
  std::optional<Procedure> procedure; // set for an adaptive block
  bool shuffle = true;
  std::string instructions;
  std::vector<std::string> groups;    // the groups that run this block; empty: every group
  bool practice = false;              // a practice block: its trials are recorded as practice (not scored)
  // A practice block repeated until a criterion ("criterion"): its design up to max_repeats times, each round in its
  // own shuffled order; once a round's share of correct answers reaches `correct`, the rounds after it are recorded
  // as skipped. Correct: the side showing the larger radius on screen (equal radii: can't tell), the odd interval.
  struct Criterion {
    double correct = 0.8;
    int max_repeats = 3;
  };
  std::optional<Criterion> criterion;
  // What the participant sees of the block - never its name, which is the experimenter's (it may give a condition
  // away): the title of the screen that opens it (1-100 printable characters; empty: "Part n of N", or "Practice",
  // as BlockTitle says), the prompt while an answer is taken (responses.prompt unless the block gives its own;
  // empty: none), and its timing (the protocol's, each field the block gives overriding it). Resolved by the parser:
  // a trial reads its block's, never the protocol's.
  std::string title;
  std::string prompt;
  Timing timing;
};

struct Scene {
  std::filesystem::path background;   // absolute, resolved against the protocol file's folder
  std::filesystem::path board_free;   // empty when not given
  std::filesystem::path calib;        // empty when not given (a picture needs none)
  ScenePhoto show = ScenePhoto::kBackground;  // which photo the trials show
  // A tracked video instead of a photo (issue 27 item 4): the take (a video file or a printf pattern of an image
  // sequence) and the folder `blurcue track` wrote for it; background, board_free and calib are then empty. So far a
  // trial shows the take's first frame with a pose, with that frame's calibration (stimulus::LoadProtocolScene).
  std::filesystem::path video, track;
  bool IsVideo() const { return !video.empty(); }
  // The photo the trials show, as `show` says (the background when there is no board_free).
  bool ShowsBoardFree() const { return show == ScenePhoto::kBoardFree && !board_free.empty(); }
  const std::filesystem::path& ShownPhoto() const { return ShowsBoardFree() ? board_free : background; }
};

struct Content {
  ContentType type = ContentType::kGrid;
  int cells = 5;                      // grid: cells per side of the drawn grid card (1-20)
  // grid: the card's width and height in mm (0: two board squares; a height of 0: square), upright on the table
  // facing the camera ("standing") or flat on it ("lying"), turned about the vertical axis by rotation_deg.
  double size_mm = 0, card_height_mm = 0, rotation_deg = 0;
  bool standing = false;
  double height_mm = 0;               // grid and ball: raised this far above the table (a card's lowest edge, a
                                      // ball's lowest point); a level height_mm (rotation_deg) sets it per trial
  // grid and ball: the blur kernel and the thesis's brightness/contrast matching of the virtual object (5.3.1.3),
  // applied in linear light (factors of the texture's values; 1 = as the texture is).
  Kernel kernel = Kernel::kGaussian;
  double brightness = 1, contrast = 1;
  // grid and ball: the thesis's "white balance" (5.3.1.3): gains of the object's red, green and blue in linear light.
  std::array<double, 3> white_balance{1, 1, 1};
  // grid and ball: how far the blur may change across an object's depth before it is blurred per pixel by depth
  // instead of with one radius at its centre (model no more than the scene needs): {"screen_px": 0.5} (the default)
  // or {"arcmin": 1}; 0 blurs every object per pixel.
  double depth_blur_threshold = 0.5;
  ThresholdUnit depth_blur_threshold_unit = ThresholdUnit::kScreenPx;
  double radius_mm = 10;              // ball
  // ball: the camera's exposure time (ms) that a moving ball's motion blur lasts (its image-space velocity x this,
  // drawn with its defocus in one kernel); 0 (the default on a photo): no motion blur. On a tracked video, when not
  // given (exposure_given false), the session takes the take's camera's exposure_ms, or half a frame of the take
  // where the camera does not state it (as `blurcue ar` does; procedure/prepare.cc).
  double exposure_ms = 0;
  bool exposure_given = false;
  std::string texture = "soccer";     // grid: grid (the 5 x 5 card) | an image path; ball: soccer | wood | a path
  std::filesystem::path image;        // picture: the image (resolved)
  // picture: photos of the real picture, one per distance: a resolved path with "{distance_m}" standing for the
  // level as %g (e.g. "photos/face-{distance_m}m.png" -> "photos/face-0.4m.png"); empty: the scene photo
  std::string real_photos;
  // picture with real_photos: the camera that took them and where it was focused (content.real_camera {camera,
  // focus_m}), so each distance's real picture has a known blur - the thin lens's - that a trial records in arcmin
  // and the simulated observer matches. real_camera_file empty: not given (the real blur is unknown).
  std::filesystem::path real_camera_file;
  std::optional<Camera> real_camera;  // read when the protocol's files are checked
  double real_focus_m = 0;
};

// A numeric level as text, as the record writes it (%g): an adjusted level's answer, a real photo's {distance_m}.
std::string LevelText(double level);

// The edges and sections a board of cols x rows squares has, as a refusal names them: "7 x 10 squares: edges 1-11,
// sections 1-10" (a section s runs from edge s to s + 1).
std::string BoardLevelsText(int cols, int rows);

// The real photo of `content` for a distance (content.real_photos with {distance_m} replaced).
std::filesystem::path RealPhotoFor(const Content& content, double distance_m);

// The protocol's practice: `count` trials drawn from one block's design. With between-subject groups that block must
// run for every group (validated): a block of one group's would show the others a condition they never run; each
// group practises its own condition in a practice block of its own ("practice": true, "groups": [...]).
struct Practice {
  int count = 0;                      // 0: no practice
  std::string block;                  // drawn from this block's design (the first block when the file names none)
  bool block_given = false;           // the file named the block (/practice/block); else it is the first block
  std::string instructions;
};

struct Responses {
  std::string left, right, cant_tell;   // forced choice; cant_tell empty: a strict 2AFC (JSON null)
  std::string previous, next, accept;   // adjustment
  std::string yes = "Y", no = "N";      // yes_no
  std::vector<std::string> rating;      // rating: one key per point of the scale, lowest first (recorded "1".."n")
  std::vector<std::string> alternatives;  // odd_one_out: one key per interval, first first (recorded "1".."n")
  // Shown on screen while an answer is taken, in a band below the stimulus (e.g. "Which side is more blurred?
  // Left or Right arrow"); empty: no band.
  std::string prompt;
  // Answers count only after the stimulus's motion (or its intervals) ended; keys pressed before are ignored and
  // the prompt appears then. false: answering any time after onset.
  bool after_motion = false;

  // The key a single-key field names ("" for none: a strict 2AFC's can't tell), and the member that holds it.
  const std::string& Key(ResponseKey field) const { return SlotOf(*this, field); }
  std::string& Slot(ResponseKey field) { return SlotOf(*this, field); }

 private:
  template <typename Self>
  static auto SlotOf(Self& r, ResponseKey field) -> decltype((r.left)) {
    switch (field) {
      case ResponseKey::kLeft: return r.left;
      case ResponseKey::kRight: return r.right;
      case ResponseKey::kCantTell: return r.cant_tell;
      case ResponseKey::kPrevious: return r.previous;
      case ResponseKey::kNext: return r.next;
      case ResponseKey::kAccept: return r.accept;
      case ResponseKey::kYes: return r.yes;
      case ResponseKey::kNo: return r.no;
    }
    return r.accept;
  }
};

// How a grid or ball trial's photo maps to the screen (a picture's frame is always fitted, 4:3, at 1 screen px per
// frame px).
enum class Scaling { kFit, kNative, kScale, kDegrees };  // "fit" | "native" | a number | width_deg

struct Display {
  int width_px = 1280, height_px = 720;
  // kFit: the whole photo, letterboxed; kNative: 1 screen px per photo px; kScale: `scale` screen px per photo px;
  // kDegrees: the photo's width spans `width_deg` of visual angle (the display profile's px per degree). A photo
  // larger than the window is cropped around what the trial shows.
  Scaling scaling = Scaling::kFit;
  double scale = 1;                   // kScale
  double width_deg = 0;               // kDegrees
  bool fullscreen = false;
  int monitor = 0;
  std::filesystem::path profile;      // the monitor's display profile (display/profile.h), resolved; empty: none
};

// A piece of participant information the protocol asks for (PsychoPy's expInfo): recorded with the session.
struct InfoField {
  std::string key;                   // [a-z0-9_], 1-40 characters
  InfoType type = InfoType::kText;
  double min = 0, max = 0;           // integer, number
  std::vector<std::string> choices;  // choice
  bool required = true;
  std::string prompt;                // what the terminal asks; default: the key
};

// Between-subject groups: each participant runs the blocks of one group (a block's "groups"; none: every group).
struct Groups {
  std::vector<std::string> names;
  // by_number: names[(number - 1) mod n]; balanced: the group with the fewest participants in the record so far
  // (store::SessionsPerGroup says who counts; the first of equals).
  GroupAssign assign = GroupAssign::kByNumber;
};

// Why `value` is not an answer to `field` ("" when it is one): a whole number in [min, max], a number, one of the
// choices, text of at most 200 characters without control characters.
std::string CheckInfoValue(const InfoField& field, const std::string& value);

struct Protocol {
  std::filesystem::path file;
  std::string name, description;
  int version = 1;
  Scene scene;
  Content content;
  std::vector<Block> blocks;          // at least one; a file without "blocks" has one block named "main"
  // Each conditions table the blocks read: its path as the protocol writes it -> its text as read. Part of the
  // protocol's version (RecordedText): a table edited between sessions is another design.
  std::map<std::string, std::string> conditions_tables;
  // The order blocks run in: "fixed" (file order), "random" (drawn with the seed) or "latin_square" (a balanced
  // Latin square over participants by their number: each block equally often in each place, and after each other).
  BlockSequence block_order = BlockSequence::kFixed;
  // How a trial is shown: each layout's word and meaning are in protocols/protocol.schema.json's layout field
  // (vocabulary.h lists them; stimulus/trial_scene.cc turns each into what a trial shows).
  Layout layout = Layout::kSideBySide;
  int alternatives = 0;               // odd_one_out: intervals per trial (3-6)
  std::vector<InfoField> participant_info;
  std::optional<Groups> groups;
  Practice practice;
  std::string instructions;
  int break_every_trials = 0;         // 0: no breaks
  std::string break_text;
  Responses responses;                // responses.prompt is the blocks' default: a trial reads Block::prompt
  Timing timing;                      // the blocks' default: a trial reads Block::timing
  Display display;
};

// The intervals a pair trial shows one after the other: 2 (two_intervals), alternatives (odd_one_out), else 0.
int IntervalCount(const Protocol& protocol);

// Trials of one block's design (crossing x repetitions x swapped copies), or kMaxTrials + 1 when it has more.
int64_t DesignTrials(const Block& block);
// P(`down` correct answers in a row come before `up` wrong ones in a row) when each answer is correct with
// probability p, independently: p^(d-1) (1 - q^u) / (p^(d-1) + q^(u-1) - p^(d-1) q^(u-1)), q = 1 - p.
double DownRunFirst(double p, int up, int down);
// The share of answers correct an up/down staircase converges to (Levitt 1971): where DownRunFirst is 1/2, by
// bisection (1-up/n-down: 0.5^(1/n)). analysis/criteria.py staircase_target is its twin.
double StaircaseTarget(int up, int down);

// Trials of a session (practice included), or kMaxTrials + 1 when it would have more.
int64_t SessionTrials(const Protocol& protocol);

// Every distinct number a trial can find by FindLevel(levels, `factor`), over all blocks, ascending: the factor's own
// levels, or the key of object levels and conditions rows.
std::set<double> NumericLevels(const Protocol& protocol, const std::string& factor);

// What a file a protocol names is read as, for ValidateOptions::check_content.
enum class FileUse { kImage, kCalibration };

struct ValidateOptions {
  bool check_files = true;            // false: skip the existence checks of referenced files
  // Set (with check_files): each scene photo, picture, texture file and calibration the protocol names, once it is
  // a regular file, is read by this, and what it returns (empty: nothing wrong) is a problem at its field, so a
  // damaged photo or calibration is named with every other problem (PrepareStudy: core's image check, calib's
  // reader); the protocol module itself reads no image or calibration.
  std::function<std::string(const std::filesystem::path&, FileUse)> check_content = nullptr;
  // > 0: the calibrated board's squares (scene.calib's board, read before the protocol: PrepareStudy), so that a
  // level naming an edge or a section past it is a problem named with every other one, not refused alone later.
  int board_cols = 0, board_rows = 0;
  // Set: the conditions tables are read from here (path as the protocol writes it -> the table's text: a recorded
  // version's "recorded_conditions", RecordedText), not from files; a path it lacks is a problem.
  const std::map<std::string, std::string>* conditions_tables = nullptr;
};

// Every problem of `json` read from `file` (used in messages and to resolve relative paths), in document order;
// empty when the protocol is valid.
std::vector<std::string> Validate(const Json& json, const std::filesystem::path& file,
                                  const ValidateOptions& options = {});

// Parses and validates; throws one Error(kInput) whose message lists every problem, one per line.
Protocol ParseProtocol(const Json& json, const std::filesystem::path& file, const ValidateOptions& options = {});

// Reads `file` and parses it as above (Error(kInput) naming the file when it cannot be read or is not JSON).
Protocol LoadProtocol(const std::filesystem::path& file, const ValidateOptions& options = {});

// The text a record keeps as the protocol's version: `text` (the file as read, which parsed into `protocol`) as it
// is when no block reads a conditions table; otherwise the same JSON with one more member, "recorded_conditions":
// {path as written: the table's text as read}, so that a table edited between sessions gives another version and
// the record names the change. A protocol file cannot itself hold that member (no such field is read).
std::string RecordedText(const std::string& text, const Protocol& protocol);

}  // namespace blurcue::protocol
