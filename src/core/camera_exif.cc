#include "core/camera_exif.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <memory>

#include <libexif/exif-data.h>
#include <libexif/exif-loader.h>
#include <opencv2/imgcodecs.hpp>

#include "core/error.h"
#include "core/image.h"
#include "core/typed.h"

namespace blurcue {

const std::vector<KnownSensor>& KnownSensors() {
  // Makers' published sensor sizes (active area), by the Model string the camera writes.
  static const std::vector<KnownSensor> kSensors = {
      {"NEX-5N", 23.4, 15.6},          // the thesis's camera (Table 4.1: 23.4 x 15.6 mm, 4592 x 3056 px)
      {"NEX-C3", 23.4, 15.6},
      {"ILCE-6000", 23.5, 15.6},
      {"ILCE-7M3", 35.6, 23.8},
      {"Canon EOS 5D Mark IV", 36.0, 24.0},
      {"Canon EOS 90D", 22.3, 14.8},
      {"Canon EOS 80D", 22.3, 14.9},
      {"NIKON D850", 35.9, 23.9},
      {"NIKON D7500", 23.5, 15.6},
      {"X-T3", 23.5, 15.6},
      {"E-M10MarkIII", 17.3, 13.0},
  };
  return kSensors;
}

namespace {

std::string Hex(ExifTag tag) {
  char b[16];
  std::snprintf(b, sizeof b, "0x%04x", unsigned(tag));
  return b;
}

struct Exif {
  ExifData* data;
  ExifByteOrder order;
  std::string file;

  ExifEntry* Find(ExifTag tag) const {
    for (int ifd = 0; ifd < EXIF_IFD_COUNT; ++ifd)
      if (ExifEntry* e = exif_content_get_entry(data->ifd[ifd], tag)) return e;
    return nullptr;
  }
  std::string Name(ExifTag tag) const {
    const char* n = exif_tag_get_name(tag);
    return std::string("EXIF ") + (n ? n : "tag") + " (" + Hex(tag) + ")";
  }
  // A number as the tag holds it: rational, short or long; nullopt when absent. Throws when present but unusable.
  std::optional<double> Number(ExifTag tag) const {
    ExifEntry* e = Find(tag);
    if (!e || e->components < 1) return std::nullopt;
    const size_t need = exif_format_get_size(e->format);
    if (need == 0 || e->size < need) throw InputError(file, Name(tag) + " is damaged");
    switch (e->format) {
      case EXIF_FORMAT_RATIONAL: {
        const ExifRational r = exif_get_rational(e->data, order);
        if (r.denominator == 0) return std::nullopt;  // 0/0 is how cameras write "unknown"
        return double(r.numerator) / r.denominator;
      }
      case EXIF_FORMAT_SRATIONAL: {
        const ExifSRational r = exif_get_srational(e->data, order);
        if (r.denominator == 0) return std::nullopt;
        return double(r.numerator) / r.denominator;
      }
      case EXIF_FORMAT_SHORT:
        return double(exif_get_short(e->data, order));
      case EXIF_FORMAT_LONG:
        return double(exif_get_long(e->data, order));
      case EXIF_FORMAT_SSHORT:
        return double(exif_get_sshort(e->data, order));
      case EXIF_FORMAT_SLONG:
        return double(exif_get_slong(e->data, order));
      case EXIF_FORMAT_BYTE:
      case EXIF_FORMAT_ASCII:
      case EXIF_FORMAT_SBYTE:
      case EXIF_FORMAT_UNDEFINED:
      case EXIF_FORMAT_FLOAT:
      case EXIF_FORMAT_DOUBLE:
        break;
    }
    throw InputError(file, Name(tag) + " has an unexpected format (" + exif_format_get_name(e->format) + ")");
  }
  std::string Text(ExifTag tag) const {
    ExifEntry* e = Find(tag);
    if (!e || e->format != EXIF_FORMAT_ASCII || !e->data) return "";
    std::string s(reinterpret_cast<const char*>(e->data), e->size);
    s = s.substr(0, s.find('\0'));
    const size_t a = s.find_first_not_of(' '), b = s.find_last_not_of(' ');
    return a == std::string::npos ? "" : OneLine(s.substr(a, b - a + 1));
  }
};

// A photo's EXIF as stored. exif_data_new_from_file "fixes" a tag whose type is not the standard's: a FocalLength
// stored as the signed rational -21/-1 became the unsigned 4294967275/4294967295 = 0.99999999534 mm. Loaded without
// that fix, each number is read with its own type's sign (Exif::Number). nullptr when the file holds no EXIF.
ExifData* LoadExifAsStored(const std::string& file) {
  std::unique_ptr<ExifLoader, void (*)(ExifLoader*)> loader(exif_loader_new(), exif_loader_unref);
  if (!loader) return nullptr;
  exif_loader_write_file(loader.get(), file.c_str());
  const unsigned char* buffer = nullptr;
  unsigned int size = 0;
  exif_loader_get_buf(loader.get(), &buffer, &size);
  if (!buffer || size == 0) return nullptr;
  ExifData* data = exif_data_new();
  if (!data) return nullptr;
  exif_data_unset_option(data, EXIF_DATA_OPTION_FOLLOW_SPECIFICATION);
  exif_data_load_data(data, buffer, size);
  return data;
}

// The sensor's size in mm, in the stored image's orientation, from the first source that gives one: --sensor-mm,
// the focal-plane resolution, the sensor table, the 35 mm equivalent (with the focal length `fl`); the source goes
// into out->sensor_source. {0, 0} when none does: why into `absent` (unless only the focal length is missing), the
// option into `options`.
std::pair<double, double> SensorSizeMm(const Exif& exif, bool have_exif,
                                       std::optional<std::pair<double, double>> sensor_mm, bool turned,
                                       double stored_w, double stored_h, const std::optional<double>& fl,
                                       ExifCamera* out_camera, std::vector<std::string>* absent,
                                       std::vector<std::string>* options) {
  ExifCamera& out = *out_camera;
  const Camera& c = out.camera;
  auto number = [&](ExifTag tag) { return have_exif ? exif.Number(tag) : std::nullopt; };
  double sw = 0, sh = 0;
  const std::optional<double> xres = number(EXIF_TAG_FOCAL_PLANE_X_RESOLUTION);
  const std::optional<double> yres = number(EXIF_TAG_FOCAL_PLANE_Y_RESOLUTION);
  const std::optional<double> unit = number(EXIF_TAG_FOCAL_PLANE_RESOLUTION_UNIT);
  const std::optional<double> fl35 = number(EXIF_TAG_FOCAL_LENGTH_IN_35MM_FILM);
  const KnownSensor* known = nullptr;
  for (const KnownSensor& k : KnownSensors())
    if (out.model == k.model) known = &k;
  if (sensor_mm) {
    sw = turned ? sensor_mm->second : sensor_mm->first, sh = turned ? sensor_mm->first : sensor_mm->second;
    out.sensor_source = "given (--sensor-mm)";
  } else if (xres && yres && *xres > 0 && *yres > 0 && unit && (*unit == 2 || *unit == 3 || *unit == 4)) {
    const double mm_per_unit = *unit == 2 ? 25.4 : *unit == 3 ? 10.0 : 1.0;  // inch, cm, mm (4: some makers)
    sw = stored_w / *xres * mm_per_unit, sh = stored_h / *yres * mm_per_unit;
    out.sensor_source = "focal-plane resolution";
  } else if (known) {
    const bool portrait = stored_h > stored_w;
    sw = portrait ? known->height_mm : known->width_mm, sh = portrait ? known->width_mm : known->height_mm;
    out.sensor_source = std::string("sensor table (") + known->model + ")";
  } else if (fl35 && *fl35 > 0 && fl) {
    // The 35 mm equivalent keeps the diagonal: 43.27 mm x f / f35; the image's sides give the aspect.
    const double diagonal = std::hypot(36.0, 24.0) * c.focal_length_mm / *fl35;
    const double aspect = stored_w / stored_h;
    sh = diagonal / std::sqrt(1 + aspect * aspect), sw = sh * aspect;
    out.sensor_source = "35 mm equivalent focal length (" + Num(*fl35) + " mm)";
    out.notes.push_back("the sensor size is approximate: EXIF rounds the 35 mm equivalent to whole mm (up to " +
                        Num(50 / *fl35) + " % here); give --sensor-mm W H from the maker's data for a better one");
  } else if (fl35 && *fl35 > 0) {
    // The 35 mm equivalent gives the sensor once the focal length (named missing above) is given.
  } else {
    // Why each source of a sensor size gave none: a tag absent, or present with a value that says "unknown".
    auto said = [&](ExifTag tag, const std::optional<double>& v, const char* why) {
      return exif.Name(tag) + (v ? " is " + Num(*v) + " (" + why + ")" : std::string(" is missing"));
    };
    absent->push_back("no sensor size (" +
                     (!(xres && *xres > 0)   ? said(EXIF_TAG_FOCAL_PLANE_X_RESOLUTION, xres, "no resolution")
                      : !(yres && *yres > 0) ? said(EXIF_TAG_FOCAL_PLANE_Y_RESOLUTION, yres, "no resolution")
                                             : said(EXIF_TAG_FOCAL_PLANE_RESOLUTION_UNIT, unit, "not inch, cm or mm")) +
                     ", " + said(EXIF_TAG_FOCAL_LENGTH_IN_35MM_FILM, fl35, "unknown") +
                     (out.model.empty() ? ", no EXIF Model"
                                        : ", model '" + out.model + "' not in the sensor table") +
                     ")");
    options->push_back("--sensor-mm W H");
  }
  return {sw, sh};
}

}  // namespace

ExifCamera CameraFromExif(const std::filesystem::path& photo, std::optional<std::pair<double, double>> sensor_mm,
                          std::optional<double> focal_length_mm, std::optional<double> f_number) {
  const std::string file = photo.string();
  // The image as calibrate decodes it (EXIF orientation applied): its size is the calibration's.
  const cv::Mat image = ReadImage(photo, cv::IMREAD_COLOR);
  std::unique_ptr<ExifData, void (*)(ExifData*)> data(LoadExifAsStored(file), exif_data_unref);
  const bool have_exif = data != nullptr;
  const Exif exif{data.get(), have_exif ? exif_data_get_byte_order(data.get()) : EXIF_BYTE_ORDER_INTEL, file};
  auto number = [&](ExifTag tag) { return have_exif ? exif.Number(tag) : std::nullopt; };

  ExifCamera out;
  Camera& c = out.camera;
  c.image_width_px = image.cols;
  c.image_height_px = image.rows;
  if (have_exif) out.make = exif.Text(EXIF_TAG_MAKE), out.model = exif.Text(EXIF_TAG_MODEL);
  // libexif reads a JPEG's EXIF only: a PNG's or a TIFF's, if it has one, is not read, and the message says so.
  std::string no_exif = "holds no EXIF";
  {
    std::ifstream in(photo, std::ios::binary);
    char magic[2] = {0, 0};
    in.read(magic, 2);
    if (!(uint8_t(magic[0]) == 0xFF && uint8_t(magic[1]) == 0xD8))
      no_exif = "is not a JPEG: its EXIF, if any, is not read (EXIF is read from JPEG files)";
  }
  // Every number calibrate needs that neither an option nor the EXIF gives is named at once, with its option.
  // A tag of 0 is the maker's "unknown" (a lens without contacts writes FocalLength 0/1): named like a missing one.
  std::vector<std::string> absent, options;
  auto needed = [&](ExifTag tag, const std::optional<double>& given, const char* option) -> std::optional<double> {
    if (given) return given;
    const std::optional<double> v = number(tag);
    if (v && *v > 0) return v;
    absent.push_back(exif.Name(tag) + (!v        ? std::string(" is missing")
                                       : *v < 0 ? " is " + Num(*v) + " (negative: a damaged or hand-made tag)"
                                                : " is " + Num(*v) + " (unknown)"));
    options.push_back(option);
    return std::nullopt;
  };
  const std::optional<double> fl = needed(EXIF_TAG_FOCAL_LENGTH, focal_length_mm, "--focal-length-mm");
  const std::optional<double> n = needed(EXIF_TAG_FNUMBER, f_number, "--f-number");
  c.focal_length_mm = fl ? *fl : 0;
  c.f_number = n ? *n : 0;
  // EXIF's pixel dimensions are the stored image's, before orientation: a portrait photo's are swapped against ours.
  const std::optional<double> px = number(EXIF_TAG_PIXEL_X_DIMENSION), py = number(EXIF_TAG_PIXEL_Y_DIMENSION);
  const std::optional<double> orientation = number(EXIF_TAG_ORIENTATION);
  const bool turned = orientation && *orientation >= 5 && *orientation <= 8;
  const double stored_w = px ? *px : turned ? image.rows : image.cols;
  const double stored_h = py ? *py : turned ? image.cols : image.rows;
  // In the stored image's orientation.
  const auto [sw, sh] = SensorSizeMm(exif, have_exif, sensor_mm, turned, stored_w, stored_h, fl, &out, &absent,
                                     &options);
  if (!options.empty()) {
    std::string give;
    for (size_t i = 0; i < options.size(); ++i)
      give += (i == 0 ? "" : i + 1 == options.size() ? " and " : ", ") + options[i];
    std::string why;
    for (const std::string& a : absent) why += (why.empty() ? "" : ", ") + a;
    throw InputError(file, (have_exif ? why : no_exif) + "; give " + give);
  }
  auto micron = [](double mm) { return std::round(mm * 1e4) / 1e4; };  // finer than any maker states
  c.sensor_width_mm = micron(turned ? sh : sw);
  c.sensor_height_mm = micron(turned ? sw : sh);
  if (turned) out.notes.push_back("the photo is stored turned (EXIF Orientation " + Num(*orientation) +
                                  "): the sensor's sides are swapped to match the image calibrate reads");

  // Seconds; what streaks a moving object in the photo (camera.json's exposure_ms). 0 or absent: unknown.
  if (const std::optional<double> t = number(EXIF_TAG_EXPOSURE_TIME); t && *t > 0) {
    if (*t * 1000 <= CameraLimits::kExposureMs[1]) c.exposure_ms = *t * 1000;
    else out.notes.push_back(exif.Name(EXIF_TAG_EXPOSURE_TIME) + " " + Num(*t) + " s is not kept (longer than a minute)");
  }
  if (const std::optional<double> d = number(EXIF_TAG_SUBJECT_DISTANCE); d && *d > 0) {
    // Metres; 0 is "unknown", 0xFFFFFFFF/1 "infinity".
    if (*d < 4e6) out.focus_distance_mm = *d * 1000;
    else out.focus_at_infinity = true;
  }
  try {
    c.Validate(file + ": ");
  } catch (const Error& e) {
    // A number refused says where it came from when that was the EXIF, and which option replaces it.
    const std::string what = e.what();
    std::string from;
    if (what.find("/focal_length_mm:") != std::string::npos && !focal_length_mm)
      from = exif.Name(EXIF_TAG_FOCAL_LENGTH) + "; give --focal-length-mm";
    else if (what.find("/f_number:") != std::string::npos && !f_number)
      from = exif.Name(EXIF_TAG_FNUMBER) + "; give --f-number";
    else if (what.find("/sensor_") != std::string::npos && !sensor_mm)
      from = "the sensor size from the " + out.sensor_source + "; give --sensor-mm W H";
    if (from.empty()) throw;
    throw Error(ErrorKind::kInput, what + " (" + from + ")");
  }
  return out;
}

}  // namespace blurcue
