#include "cli/placed_objects.h"

#include <cmath>
#include <map>
#include <optional>

#include "core/error.h"
#include "core/image.h"
#include "core/typed.h"
#include "scene/stimuli.h"

namespace blurcue::cli {
namespace {

// "X,Y[,A[,B]]" in mm: 2 to `most` numbers. Error(kUsage) naming the option and the text.
std::vector<double> MmList(const std::string& option, const std::string& text, size_t most, const char* form) {
  std::vector<double> v;
  bool ok = true;
  for (size_t start = 0; ok;) {
    const size_t comma = text.find(',', start);
    const std::optional<double> n = ParseDecimal(text.substr(start, comma == std::string::npos ? comma : comma - start));
    ok = n && std::abs(*n) <= 1e5;
    if (ok) v.push_back(*n);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (!ok) v.clear();
  if (v.size() < 2 || v.size() > most)
    throw Error(ErrorKind::kUsage, option + " " + Echo(text) + ": expected " + form + " (mm, numbers within 1e5)");
  return v;
}

}  // namespace

std::vector<stimulus::PlacedObject> PlaceObjects(const ObjectOptions& options, std::vector<std::string>* given) {
  const size_t most = stimulus::kMaxPlacedObjects;
  if (options.balls.size() + options.cards.size() > most)
    throw Error(ErrorKind::kUsage, std::to_string(options.balls.size() + options.cards.size()) +
                                       " --ball and --card options: at most " + std::to_string(most) + " objects a run");
  std::vector<stimulus::PlacedObject> objects;
  given->clear();
  if (!options.objects_file.empty()) {
    objects = stimulus::LoadPlacedObjects(options.objects_file);
    for (size_t i = 0; i < objects.size(); ++i)
      given->push_back(options.objects_file + ": /objects/" + std::to_string(i));
    if (objects.size() + options.balls.size() + options.cards.size() > most)
      throw InputError(options.objects_file, std::to_string(objects.size()) + " objects and " +
                                                 std::to_string(options.balls.size() + options.cards.size()) +
                                                 " on the command line: at most " + std::to_string(most) +
                                                 " objects a run");
  }
  // One texture per image, however many objects wear it: decoded once, and one GL texture (its identity).
  std::map<std::string, scene::SurfaceTexture> textures;
  auto add = [&](const char* kind, const scene::VirtualObject& o, const std::string& texture) {
    stimulus::PlacedObject p;
    int n = 1;
    for (const auto& q : objects) n += q.object.kind == o.kind;
    p.name = kind + std::to_string(n);
    p.object = o;
    auto known = textures.find(texture);
    if (known == textures.end())
      known = textures.emplace(texture, scene::SurfaceTexture(ReadImage(scene::ResolveStimulus(texture)))).first;
    p.object.texture = known->second;
    objects.push_back(std::move(p));
  };
  for (const std::string& b : options.balls) {
    const std::vector<double> v = MmList("--ball", b, 3, "X,Y[,RADIUS]");
    if (v.size() == 3 && !(v[2] > 0)) throw Error(ErrorKind::kUsage, "--ball " + Echo(b) + ": RADIUS must be > 0");
    add("ball", stimulus::BallAt(v[0], v[1], v.size() == 3 ? v[2] : 10), options.ball_texture);
    given->push_back("--ball " + Echo(b));
  }
  for (const std::string& c : options.cards) {
    const std::vector<double> v = MmList("--card", c, 4, "X,Y[,WIDTH[,HEIGHT]]");
    const double w = v.size() >= 3 ? v[2] : 50, h = v.size() == 4 ? v[3] : w;
    if (!(w > 0 && h > 0)) throw Error(ErrorKind::kUsage, "--card " + Echo(c) + ": WIDTH and HEIGHT must be > 0");
    add("card", stimulus::StandingCardAt(v[0], v[1], w, h, 0), options.card_texture);
    given->push_back("--card " + Echo(c));
  }
  if (objects.empty()) throw Error(ErrorKind::kUsage, "no objects: give --ball, --card or --objects");
  return objects;
}

void AddObjectOptions(CLI::App* cmd, ObjectOptions* o) {
  cmd->add_option("--ball", o->balls, "a ball resting on the board: X,Y[,RADIUS] in board mm (radius 10)");
  cmd->add_option("--card", o->cards,
                  "a card standing on the board facing the camera: X,Y[,WIDTH[,HEIGHT]] in board mm (50 x 50)");
  cmd->add_option("--objects", o->objects_file, "objects from a JSON file (docs/ar.md)")->check(CLI::ExistingFile);
  cmd->add_option("--ball-texture", o->ball_texture, "texture of --ball balls: soccer, wood or an image")
      ->capture_default_str();
  cmd->add_option("--card-texture", o->card_texture, "texture of --card cards: a stimulus name or an image")
      ->capture_default_str();
}

void GuardObjectInputs(OutputGuard& guard, const ObjectOptions& o) {
  if (!o.objects_file.empty()) guard.Input("--objects", o.objects_file);
  if (!o.balls.empty()) guard.Input("--ball-texture", scene::ResolveStimulus(o.ball_texture));
  if (!o.cards.empty()) guard.Input("--card-texture", scene::ResolveStimulus(o.card_texture));
}

}  // namespace blurcue::cli
