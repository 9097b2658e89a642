#include "display/profile.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <type_traits>

#include "core/error.h"
#include "core/limits.h"
#include "core/typed.h"

namespace blurcue::display {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string Got(const Json& value) {
  std::string text = value.dump();
  return text.size() > 60 ? text.substr(0, 57) + "..." : text;
}

// Collects every problem of a profile file, each naming its JSON pointer, the rule and the value.
class Checker {
 public:
  explicit Checker(const std::filesystem::path& file) : file_(file.string()) {}
  std::vector<std::string> problems;

  void Problem(const std::string& pointer, const std::string& what) {
    problems.push_back(file_ + ": " + pointer + ": " + what);
  }

  // A number within [lo, hi] (unit in the message); writes it to `out` when valid.
  template <typename T>
  void Number(const Json& object, const std::string& key, double lo, double hi, const std::string& unit, T* out) {
    const auto it = object.find(key);
    if (it == object.end()) return;
    const std::string pointer = "/" + key;
    const bool integer = std::is_integral_v<T>;
    if (!it->is_number() || (integer && !it->is_number_integer())) {
      Problem(pointer, std::string("must be ") + (integer ? "a whole number" : "a number") + " of " + unit +
                           ", got " + Got(*it));
      return;
    }
    const double value = it->get<double>();
    if (!std::isfinite(value) || value < lo || value > hi) {
      char range[96];
      std::snprintf(range, sizeof range, "must be in [%g, %g] %s, got ", lo, hi, unit.c_str());
      Problem(pointer, range + Got(*it));
      return;
    }
    *out = static_cast<T>(value);
  }

 private:
  std::string file_;
};

double SrgbDecode(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }
double SrgbEncode(double l) { return l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1 / 2.4) - 0.055; }

// a and k of L = a + k x (x = v^gamma) by least squares, and the residual sum of squares.
void LinearFit(const std::vector<LuminancePoint>& points, double gamma, double* a, double* k, double* sse) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = static_cast<double>(points.size());
  for (const auto& p : points) {
    const double x = std::pow(p.level, gamma);
    sx += x, sy += p.cd_m2, sxx += x * x, sxy += x * p.cd_m2;
  }
  const double det = n * sxx - sx * sx;
  *k = det > 0 ? (n * sxy - sx * sy) / det : 0;
  *a = (sy - *k * sx) / n;
  *sse = 0;
  for (const auto& p : points) {
    const double r = *a + *k * std::pow(p.level, gamma) - p.cd_m2;
    *sse += r * r;
  }
}

}  // namespace

std::string ToString(TransferKind kind) {
  switch (kind) {
    case TransferKind::kGamma: return "gamma";
    case TransferKind::kMeasured: return "measured";
    case TransferKind::kSrgb: break;
  }
  return "srgb";
}

Profile DefaultProfile() { return Profile{}; }

GammaFit FitGamma(const std::vector<LuminancePoint>& points) {
  if (points.size() < 3) throw Error(ErrorKind::kInput, "a measured transfer needs at least 3 points");
  // The sum of squares is smooth and unimodal in gamma over the range displays have: a coarse scan, then golden
  // section around the best grid point.
  auto sse_at = [&](double gamma) {
    double a, k, sse;
    LinearFit(points, gamma, &a, &k, &sse);
    return sse;
  };
  double best = 1;
  for (double g = 1; g <= 4.0001; g += 0.05)
    if (sse_at(g) < sse_at(best)) best = g;
  double lo = std::max(1.0, best - 0.05), hi = std::min(4.0, best + 0.05);
  const double ratio = (std::sqrt(5.0) - 1) / 2;
  for (int i = 0; i < 60; ++i) {
    const double x1 = hi - ratio * (hi - lo), x2 = lo + ratio * (hi - lo);
    if (sse_at(x1) < sse_at(x2)) hi = x2;
    else lo = x1;
  }
  GammaFit fit;
  fit.gamma = 0.5 * (lo + hi);
  double sse;
  LinearFit(points, fit.gamma, &fit.a, &fit.k, &sse);
  if (!(fit.k > 0)) throw Error(ErrorKind::kInput, "the measured luminance does not rise with the drive level");
  fit.rms_cd_m2 = std::sqrt(sse / static_cast<double>(points.size()));
  return fit;
}

std::vector<std::string> ValidateProfile(const Json& json, const std::filesystem::path& file) {
  Checker check(file);
  if (!json.is_object()) {
    check.Problem("/", "a display profile must be a JSON object, got " + Got(json));
    return check.problems;
  }
  static const std::vector<std::string> kKnown = {"name",      "width_px",    "height_px",  "width_mm",
                                                  "height_mm", "distance_mm", "refresh_hz", "transfer"};
  for (const auto& item : json.items())
    if (std::find(kKnown.begin(), kKnown.end(), item.key()) == kKnown.end())
      check.Problem("/" + item.key(), "unknown key (known: name, width_px, height_px, width_mm, height_mm, "
                                      "distance_mm, refresh_hz, transfer), got " + Got(item.value()));
  Profile p;
  if (json.contains("name") && (!json["name"].is_string() || json["name"].get<std::string>().empty())) {
    check.Problem("/name", "must be a non-empty string, got " + Got(json["name"]));
  } else if (json.contains("name")) {
    // The name is recorded with every session and printed by validate, run and sessions: one line of text, as a
    // protocol's name. A 100,000-character name or one holding a newline or an escape was taken as it was.
    const std::string& name = json["name"].get_ref<const std::string&>();
    if (name.size() > kMaxNameChars)
      check.Problem("/name", "must be at most " + std::to_string(kMaxNameChars) + " characters, got " + Echo(name));
    else if (!IsPrintableUtf8(name))
      check.Problem("/name", "must not contain control characters (line breaks, tabs, escapes), got " + Echo(name));
  }
  check.Number(json, "width_px", kMinWidthPx, kMaxWidthPx, "px", &p.width_px);
  check.Number(json, "height_px", kMinHeightPx, kMaxHeightPx, "px", &p.height_px);
  check.Number(json, "width_mm", 50, 20000, "mm", &p.width_mm);
  check.Number(json, "height_mm", 30, 20000, "mm", &p.height_mm);
  check.Number(json, "distance_mm", 100, 20000, "mm", &p.distance_mm);
  check.Number(json, "refresh_hz", 20, 1000, "Hz", &p.refresh_hz);
  if (json.contains("width_px") != json.contains("height_px"))
    check.Problem(json.contains("width_px") ? "/height_px" : "/width_px",
                  "is required with the other resolution field (a resolution is width and height)");
  if (json.contains("width_mm") != json.contains("height_mm"))
    check.Problem(json.contains("width_mm") ? "/height_mm" : "/width_mm",
                  "is required with the other size field (a size is width and height)");
  // Square pixels: the two pitches agree within 5 % (else a size or a resolution is mistyped).
  const double pitch_x = p.width_mm / p.width_px, pitch_y = p.height_mm / p.height_px;
  if (check.problems.empty() && std::abs(pitch_x / pitch_y - 1) > 0.05) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "width and height give pixels of %.4f x %.4f mm, not square: check width_mm/height_mm against "
                  "the resolution", pitch_x, pitch_y);
    check.Problem("/height_mm", text);
  }
  if (json.contains("transfer")) {
    const Json& t = json["transfer"];
    const std::string kinds = "\"srgb\", \"gamma\" (with gamma) or \"measured\" (with points)";
    if (!t.is_object() || !t.contains("kind") || !t["kind"].is_string()) {
      check.Problem("/transfer", "must be an object with a kind: " + kinds + ", got " + Got(t));
    } else {
      const std::string kind = t["kind"].get<std::string>();
      std::vector<std::string> allowed = {"kind"};
      if (kind == "gamma") {
        allowed.push_back("gamma");
        if (!t.contains("gamma")) check.Problem("/transfer/gamma", "is required for a gamma transfer");
        else if (!t["gamma"].is_number() || !(t["gamma"].get<double>() >= 1 && t["gamma"].get<double>() <= 4))
          check.Problem("/transfer/gamma", "must be in [1, 4], got " + Got(t["gamma"]));
      } else if (kind == "measured") {
        allowed.push_back("points");
        const Json* points = t.contains("points") ? &t["points"] : nullptr;
        if (!points || !points->is_array() || points->size() < 3 || points->size() > 256) {
          check.Problem("/transfer/points", "must be 3 to 256 [drive level 0..1, cd/m^2] pairs, got " +
                                                (points ? Got(*points) : std::string("nothing")));
        } else {
          double last_level = -1;
          for (size_t i = 0; i < points->size(); ++i) {
            const Json& pt = (*points)[i];
            const std::string ptr = "/transfer/points/" + std::to_string(i);
            if (!pt.is_array() || pt.size() != 2 || !pt[0].is_number() || !pt[1].is_number()) {
              check.Problem(ptr, "must be [drive level 0..1, cd/m^2], got " + Got(pt));
              continue;
            }
            const double level = pt[0].get<double>(), cd = pt[1].get<double>();
            if (!(level >= 0 && level <= 1) || level <= last_level)
              check.Problem(ptr, "drive levels must rise within [0, 1], got " + Got(pt));
            if (!(cd >= 0 && cd <= 100000)) check.Problem(ptr, "luminance must be in [0, 100000] cd/m^2, got " + Got(pt));
            last_level = level;
          }
        }
      } else if (kind != "srgb") {
        check.Problem("/transfer/kind", "must be " + kinds + ", got " + Got(t["kind"]));
      }
      for (const auto& item : t.items())
        if (std::find(allowed.begin(), allowed.end(), item.key()) == allowed.end())
          check.Problem("/transfer/" + item.key(), "is not a field of a " + kind + " transfer, got " + Got(item.value()));
    }
  }
  return check.problems;
}

Profile ParseProfile(const Json& json, const std::filesystem::path& file) {
  std::vector<std::string> problems = ValidateProfile(json, file);
  Profile p;
  p.file = file;
  if (problems.empty()) {
    if (json.contains("name")) p.name = json["name"].get<std::string>();
    else if (!file.empty()) p.name = file.stem().string();
    auto take = [&](const char* key, auto* out) {
      if (json.contains(key)) *out = json[key].get<std::remove_pointer_t<decltype(out)>>();
    };
    take("width_px", &p.width_px);
    take("height_px", &p.height_px);
    take("width_mm", &p.width_mm);
    take("height_mm", &p.height_mm);
    take("distance_mm", &p.distance_mm);
    take("refresh_hz", &p.refresh_hz);
    if (json.contains("transfer")) {
      const Json& t = json["transfer"];
      const std::string kind = t["kind"].get<std::string>();
      if (kind == "gamma") {
        p.transfer.kind = TransferKind::kGamma;
        p.transfer.fit.gamma = t["gamma"].get<double>();
      } else if (kind == "measured") {
        p.transfer.kind = TransferKind::kMeasured;
        for (const Json& pt : t["points"]) p.transfer.points.push_back({pt[0].get<double>(), pt[1].get<double>()});
        try {
          p.transfer.fit = FitGamma(p.transfer.points);
        } catch (const Error& e) {
          problems.push_back(file.string() + ": /transfer/points: " + e.what());
        }
      }
    }
  }
  if (!problems.empty()) {
    if (problems.size() > 1) problems.push_back("(" + std::to_string(problems.size()) + " problems)");
    throw Error(ErrorKind::kInput, std::move(problems));
  }
  return p;
}

Profile LoadProfile(const std::filesystem::path& file) { return ParseProfile(ReadJsonFile(file), file); }

Json ToJson(const Profile& p) {
  Json t = {{"kind", ToString(p.transfer.kind)}};
  if (p.transfer.kind == TransferKind::kGamma) t["gamma"] = p.transfer.fit.gamma;
  if (p.transfer.kind == TransferKind::kMeasured) {
    Json points = Json::array();
    for (const auto& pt : p.transfer.points) points.push_back({pt.level, pt.cd_m2});
    t["points"] = points;
    t["fit"] = {{"a_cd_m2", p.transfer.fit.a}, {"k_cd_m2", p.transfer.fit.k}, {"gamma", p.transfer.fit.gamma},
                {"rms_cd_m2", p.transfer.fit.rms_cd_m2}};
  }
  return {{"name", p.name},           {"file", p.file.string()},     {"width_px", p.width_px},
          {"height_px", p.height_px}, {"width_mm", p.width_mm},      {"height_mm", p.height_mm},
          {"distance_mm", p.distance_mm}, {"refresh_hz", p.refresh_hz}, {"px_per_deg", PxPerDeg(p)},
          {"transfer", t}};
}

double MmPerPx(const Profile& p) { return p.width_mm / p.width_px; }

double PxPerDeg(const Profile& p) { return 2 * p.distance_mm * std::tan(0.5 * kPi / 180) / MmPerPx(p); }

double ArcminOfScreenPx(const Profile& p, double px) {
  return 2 * std::atan(0.5 * px * MmPerPx(p) / p.distance_mm) * 180 / kPi * 60;
}

double ScreenPxOfArcmin(const Profile& p, double arcmin) {
  return 2 * p.distance_mm * std::tan(0.5 * arcmin / 60 * kPi / 180) / MmPerPx(p);
}

double DriveLevel(const Transfer& t, double linear) {
  linear = std::clamp(linear, 0.0, 1.0);
  switch (t.kind) {
    case TransferKind::kSrgb: return SrgbEncode(linear);
    // Relative luminance spans the fitted range L(0)..L(1): (L - a) / k = v^gamma.
    case TransferKind::kGamma:
    case TransferKind::kMeasured: return std::pow(linear, 1 / t.fit.gamma);
  }
  return linear;
}

double RelativeLuminance(const Transfer& t, double level) {
  level = std::clamp(level, 0.0, 1.0);
  switch (t.kind) {
    case TransferKind::kSrgb: return SrgbDecode(level);
    case TransferKind::kGamma:
    case TransferKind::kMeasured: return std::pow(level, t.fit.gamma);
  }
  return level;
}

}  // namespace blurcue::display
