#pragma once
// The protocol parser's internals, shared by the files it is split into (protocol.cc, parser.cc, parse_levels.cc,
// parse_blocks.cc, parse_presentation.cc); not part of the module's interface.
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/json_io.h"
#include "protocol/protocol.h"

namespace blurcue::protocol::detail {
namespace fs = std::filesystem;

// Edges a board can have: 101 for a board 100 squares long (the thesis's 7 x 10 board has 11, figure 4.10). A
// session checks its levels against the calibrated board's own count (session/stimulus.cc DescribeTrial).
const int kEdges = 101;

// Limits that keep validation itself linear and its report readable whatever the file holds.
const size_t kMaxProblems = 50;         // reported; the rest are counted
const size_t kMaxBlocks = 100;
const size_t kMaxFactors = 16;
const size_t kMaxLevels = 1000;         // per factor: more than a sitting could show
const size_t kMaxAdjustLevels = 50;     // each is low-passed up front: ~0.1 s apiece at 1280 px, ~1 s at 4K
const size_t kMaxTextChars = 2000;      // instructions: about what a screen holds
const size_t kMaxPathChars = 4096;

// `key` as a JSON pointer token (RFC 6901: ~ as ~0, / as ~1).
std::string Escape(const std::string& key);
// `value` as compact JSON of at most about 80 characters (cut at a character, "..." when cut): what a problem got.
std::string Got(const Json& value);
// "[0.1, 100] cm/s": a closed range and its unit.
std::string Range(double lo, double hi, const std::string& unit);

// A fixed blur radius: the thesis's measured radii reach ~17 px; 100 px blurs a whole object away.
const double kMaxFixedRadiusPx = 100;
// A blur source: a word of BlurSourceWords() (none, measured, ...), a radius in photo px, {"screen_px": r} or
// {"arcmin": r}.
bool IsBlurSource(const Json& v);
// Names whose values CheckLevelValue knows: a level of a factor so named is that value, never an object.
bool IsValueName(const std::string& name);
const std::vector<std::string>& ValueNames();  // the names IsValueName knows, in one list
// A label: recorded with each trial but read by nothing else (id, label, label_*), so any value goes.
bool IsLabelName(const std::string& name);
// The names a factor, an object level's key or a conditions column may have that are read (ValueNames, id, label):
// the candidates of a misspelt one's did-you-mean.
const std::vector<std::string>& ReadNames();
// Every name IsKeyName takes, as a list (the candidates of a misspelt key's did-you-mean).
const std::vector<std::string>& KeyNames();
// A key name a station knows: A-Z, 0-9, Left, Right, Up, Down, Space, Return, Tab, Backspace, F1-F12, KP_0-KP_9.
bool IsKeyName(const std::string& key);

// Walks the JSON once, filling a Protocol and collecting every problem rather than stopping at the first.
class Parser {
 public:
  Parser(const fs::path& file, const ValidateOptions& options) : file_(file), options_(options) {
    base_ = file.has_parent_path() ? file.parent_path() : fs::path(".");
  }

  std::vector<std::string> problems;  // each once, in first order, at most kMaxProblems
  size_t more_problems = 0;           // found beyond kMaxProblems

  // Fields inherited by several blocks are checked once per block: each message is kept once.
  void Problem(const std::string& ptr, const std::string& what);
  void Problem(const std::string& ptr, const std::string& what, const Json& got);

  // True if `v` is an object; reports keys outside `known` (with the nearest known key as a hint).
  bool Object(const Json& v, const std::string& ptr, const std::vector<std::string>& known);

  const Json* Field(const Json& obj, const std::string& key, const std::string& ptr, bool required);

  std::optional<std::string> String(const Json& obj, const std::string& key, const std::string& ptr, bool required,
                                    const std::vector<std::string>& allowed = {});

  // A word of the vocabulary E (vocabulary.h): a string among Words<E>(), reported as String reports it.
  template <typename E>
  std::optional<E> Word(const Json& obj, const std::string& key, const std::string& ptr, bool required) {
    const std::optional<std::string> word = String(obj, key, ptr, required, Words<E>());
    return word ? ParseWord<E>(*word) : std::nullopt;
  }

  // An integer in [min, max]; `unit` (e.g. "px", "trials") goes into the message.
  std::optional<int> Int(const Json& obj, const std::string& key, const std::string& ptr, bool required, int min,
                         int max, const std::string& unit = "");

  // A finite number in [min, max]; `unit` goes into the message.
  std::optional<double> Number(const Json& obj, const std::string& key, const std::string& ptr, bool required,
                               double min, double max, const std::string& unit);

  // True for an integer in [min, max], whether stored signed or unsigned (never wrapped).
  static bool IntegerIn(const Json& v, int64_t min, int64_t max);
  static bool NumberIn(const Json& v, double min, double max);

  // A string of at most `max_chars` bytes; `one_line`: without control characters (names, keys, paths).
  // A name (the study's, a block's): Text of 1 to kMaxNameChars characters on one line that UnsafeIdReason takes.
  std::optional<std::string> Name(const Json& obj, const std::string& key, const std::string& ptr, bool required);
  std::optional<std::string> Text(const Json& obj, const std::string& key, const std::string& ptr, bool required,
                                  size_t max_chars, bool one_line);

  std::optional<bool> Bool(const Json& obj, const std::string& key, const std::string& ptr);

  // A path relative to the protocol file's folder; checked for existence unless options say otherwise, and, with
  // `use`, its content by options' check_content.
  fs::path Path(const Json& obj, const std::string& key, const std::string& ptr, bool required,
                std::optional<FileUse> use = std::nullopt);

  // A regular file: not missing, not a folder, not a device (/dev/zero) or FIFO that a reader would wait on.
  // What is in it (an image that decodes, a calibration that parses) is checked before a session (PrepareSession),
  // and here where the options' check_content reads it (Path's `use`).
  bool CheckFile(const fs::path& resolved, const std::string& ptr, const Json& got);

  // The protocol `json` describes; its problems are in `problems` (and counted in more_problems) afterwards.
  Protocol Parse(const Json& json);

 private:
  void ParseScene(const Json& v, const std::string& ptr, Protocol* p);
  void ParseContent(const Json& v, const std::string& ptr, Protocol* p);
  std::vector<Factor> ParseFactors(const Json& v, const std::string& ptr);
  // `where`, if given, follows the value in a problem (a conditions table's " (FILE line N, column C)").
  void CheckLevelValue(const std::string& name, const Json& v, const std::string& ptr, const std::string& where = "");
  std::optional<Adjustment> ParseAdjust(const Json& v, const std::string& ptr);
  void ParseRealCamera(const Json& v, const std::string& ptr, const Json& content, Protocol* p);
  std::optional<Procedure> ParseProcedure(const Json& v, const std::string& ptr);
  std::vector<Factor> ParseConditions(const Json& v, const std::string& ptr);
  // Reports `name` (a factor, an object level's key, a conditions column: `what`) at `ptr` when nothing reads it and
  // it is no label, with the nearest read name; `where` goes before the message (a CSV file's line and column).
  void CheckReadName(const std::string& name, const std::string& what, const std::string& ptr,
                     const std::string& where = "");
  // Timing fields given in `v` (the protocol's, or a block's that overrides them) into `t`; `blocks` are those the
  // timing applies to, for the fields that only some blocks or layouts read.
  void ParseTiming(const Json& v, const std::string& ptr, const Protocol& p, const std::vector<const Block*>& blocks,
                   Timing* t);
  void ParseInfo(const Json& v, const std::string& ptr, Protocol* p);
  void ParseGroups(const Json& v, const Json& top, const std::string& ptr, Protocol* p);
  // A block's "sides", checked, and typed as far as it is valid.
  std::optional<Block::Sides> ParseSides(const Json& v, const std::string& ptr);
  // Fills `b` from `obj` at `ptr`, falling back to the protocol-level defaults in `top`.
  void ParseBlock(const Json& obj, const std::string& ptr, const Json& top, Block* b);
  // ParseBlock's part that reads only the block's own fields (after its design: task, factors, sides, procedure).
  void ParseBlockRun(const Json& obj, const std::string& ptr, Block* b);
  void ParseResponses(const Json& v, const std::string& ptr, const std::set<Task>& tasks, const Protocol& p,
                      Responses* r);
  // Parse's parts, in the order Parse calls them (the order of the problems they report).
  bool ParseContentAndScene(const Json& json, Protocol* p);  // true when the content type is given and valid
  void ParseBlocks(const Json& json, Protocol* p);
  void ParsePractice(const Json& json, Protocol* p);
  void ParseLayout(const Json& json, bool typed, Protocol* p);
  void CheckRealPhotos(const Json& json, const Protocol& p);
  void ParseResponsesAndTiming(const Json& json, Protocol* p);
  void ParseDisplay(const Json& json, bool typed, Protocol* p);
  void CheckDesign(const Protocol& p);
  // CheckDesign's parts, one per kind of check, in the order it calls them.
  void CheckGroups(const Protocol& p);
  void CheckBlockLevels(const Protocol& p, const Block& b);
  void CheckBlockLayout(const Protocol& p, const Block& b);
  void CheckSessionSize(const Protocol& p);
  void CheckGroupPractice(const Protocol& p);
  static bool Provides(const Block& b, const std::string& name);

  fs::path file_, base_;
  ValidateOptions options_;
  std::map<std::string, std::string> tables_;  // each conditions table read: its path as written -> its text
  std::set<std::string> reported_;
  // A conditions table's rows and cells are levels at pointers that exist in no file the experimenter wrote
  // (/blocks/0/conditions/row/K/COLUMN): each is named by where it is written instead ("rows.csv line 7, column
  // height_mm"), so a table that several blocks use reports a bad cell once.
  std::map<std::string, std::string> table_places_;
  size_t calls_ = 0;  // problems found, repeats included
};

}  // namespace blurcue::protocol::detail
