#include "lib/photometry/tm25.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/input_file.h"
#include "core/log.h"

namespace lumislab {
namespace {

// Appends code point c as UTF-8 (a value outside Unicode as U+FFFD).
void AppendUtf8(char32_t c, std::string* s) {
  if (c > 0x10FFFF || (c >= 0xD800 && c <= 0xDFFF)) c = 0xFFFD;
  if (c < 0x80) {
    *s += char(c);
  } else if (c < 0x800) {
    *s += char(0xC0 | (c >> 6));
    *s += char(0x80 | (c & 0x3F));
  } else if (c < 0x10000) {
    *s += char(0xE0 | (c >> 12));
    *s += char(0x80 | ((c >> 6) & 0x3F));
    *s += char(0x80 | (c & 0x3F));
  } else {
    *s += char(0xF0 | (c >> 18));
    *s += char(0x80 | ((c >> 12) & 0x3F));
    *s += char(0x80 | ((c >> 6) & 0x3F));
    *s += char(0x80 | (c & 0x3F));
  }
}

static_assert(sizeof(float) == 4 && sizeof(char32_t) == 4, "TM-25 needs 32-bit floats");
constexpr int kTm25Version = 2013;
constexpr size_t kTextChars = 1000;       // each description field: 1000 UTF-32 characters
constexpr size_t kColumnNameBytes = 512;  // each additional column's name (4.7.5)
constexpr int kMaxSpectra = 1 << 16;
constexpr int kMaxExtraItems = 1 << 10;

bool LittleEndian() {
  const uint32_t one = 1;
  unsigned char b;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

// Sequential reads of the file's bytes; a read past the end names the field.
class Reader {
 public:
  Reader(const std::string& path) : path_(path), in_(path, std::ios::binary) {
    if (!in_) throw IoError(path, "cannot open");
    in_.seekg(0, std::ios::end);
    size_ = uint64_t(in_.tellg());
    in_.seekg(0);
  }
  void Bytes(void* out, size_t n, const std::string& field) {
    if (pos_ + n > size_ || !in_.read(static_cast<char*>(out), std::streamsize(n)))
      throw BadInput(path_ + ": " + field +
                     ": the file ends before it (truncated: " + std::to_string(size_) + " bytes)");
    pos_ += n;
  }
  // Passes over n bytes without reading them: a size from the header is checked against the
  // file before anything is done with it (fuzz_tm25 found a text block size of 2^31 allocated
  // as a buffer before the read found the file short).
  void Skip(uint64_t n, const std::string& field) {
    if (n > Left())
      throw BadInput(path_ + ": " + field +
                     ": the file ends before it (truncated: " + std::to_string(size_) + " bytes, " +
                     std::to_string(n) + " needed from byte " + std::to_string(pos_) + ")");
    in_.seekg(std::streamoff(n), std::ios::cur);
    pos_ += n;
  }
  template <typename T>
  T Value(const std::string& field) {
    T v;
    Bytes(&v, sizeof v, field);
    return v;
  }
  int32_t Flag(const std::string& field) {
    const int32_t v = Value<int32_t>(field);
    if (v != 0 && v != 1) throw InputError(path_, field, "0 or 1", std::to_string(v));
    return v;
  }
  std::string Text(size_t chars, const std::string& field) {
    std::vector<char32_t> buffer(chars);
    Bytes(buffer.data(), chars * 4, field);
    std::string s;
    for (char32_t c : buffer) {
      if (c == 0) break;
      AppendUtf8(c, &s);
    }
    return s;
  }
  uint64_t Left() const { return size_ - pos_; }
  uint64_t Position() const { return pos_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::ifstream in_;
  uint64_t size_ = 0;
  uint64_t pos_ = 0;
};

void PutBytes(std::string* out, const void* p, size_t n) {
  out->append(static_cast<const char*>(p), n);
}
template <typename T>
void Put(std::string* out, T v) {
  PutBytes(out, &v, sizeof v);
}
// UTF-32 of the UTF-8 text `s`, at most `chars` characters, zero-padded; a byte that does not
// start a valid UTF-8 sequence is U+FFFD (the replacement character).
void PutText(std::string* out, const std::string& s, size_t chars) {
  std::vector<char32_t> text;
  for (size_t k = 0; k < s.size() && text.size() < chars;) {
    const unsigned char b = static_cast<unsigned char>(s[k]);
    const int n = b < 0x80 ? 1 : (b >> 5) == 6 ? 2 : (b >> 4) == 14 ? 3 : (b >> 3) == 30 ? 4 : 0;
    char32_t c = n == 1 ? b : n == 2 ? b & 0x1F : n == 3 ? b & 0x0F : b & 0x07;
    bool valid = n > 0 && k + n <= s.size();
    for (int m = 1; valid && m < n; ++m) {
      const unsigned char x = static_cast<unsigned char>(s[k + m]);
      valid = (x & 0xC0) == 0x80;
      c = (c << 6) | (x & 0x3F);
    }
    text.push_back(valid && c <= 0x10FFFF ? c : 0xFFFD);
    k += valid ? n : 1;
  }
  for (size_t k = 0; k < chars; ++k) Put<char32_t>(out, k < text.size() ? text[k] : 0);
}

}  // namespace

double Tm25RaySet::FluxSum() const {
  double sum = 0;
  for (const Tm25Ray& r : rays) sum += r.flux;
  return sum;
}

Tm25RaySet ReadTm25(const std::string& path) {
  if (!LittleEndian()) throw Failure("TM-25 files are little-endian; this machine is not");
  CheckInputFile(path, "TM-25 ray file");
  Reader f(path);
  Tm25RaySet set;
  char type[4];
  f.Bytes(type, 4, "file type (4.7.1.1)");
  if (std::memcmp(type, "TM25", 4) != 0)
    throw InputError(path, "file type (4.7.1.1)", "\"TM25\"", "other bytes (not a TM-25 file)");
  const int32_t version = f.Value<int32_t>("file version (4.7.1.2)");
  if (version != kTm25Version)
    throw InputError(path, "file version (4.7.1.2)", "2013", std::to_string(version));
  set.creation_method = f.Value<int32_t>("creation method (4.7.1.3)");
  set.luminous_flux_lm = f.Value<float>("luminous flux (4.7.1.4)");
  set.radiant_flux_w = f.Value<float>("radiant flux (4.7.1.5)");
  for (double v : {set.luminous_flux_lm, set.radiant_flux_w})
    if (v < 0 || std::isinf(v))
      throw InputError(path, "total flux (4.7.1.4/5)", "a number >= 0 or NaN", Num(v, 8));
  const uint64_t n_rays = f.Value<uint64_t>("number of rays (4.7.1.6)");
  char date[28];
  f.Bytes(date, 28, "date and time (4.7.1.7)");
  set.date_time.assign(date, strnlen(date, 28));
  f.Value<int32_t>("ray start position (4.7.1.8)");
  const int32_t spectrum = f.Value<int32_t>("spectral data identifier (4.7.1.9)");
  if (spectrum < 0 || spectrum > 4)
    throw InputError(path, "spectral data identifier (4.7.1.9)", "0 to 4",
                     std::to_string(spectrum));
  f.Value<float>("single wavelength (4.7.1.10)");
  f.Value<float>("minimum wavelength (4.7.1.11)");
  f.Value<float>("maximum wavelength (4.7.1.12)");
  const int32_t n_spectra = f.Value<int32_t>("number of spectral tables (4.7.1.13)");
  if (n_spectra < 0 || n_spectra > kMaxSpectra)
    throw InputError(path, "number of spectral tables (4.7.1.13)",
                     "0 to " + std::to_string(kMaxSpectra), std::to_string(n_spectra));
  const int32_t n_extra = f.Value<int32_t>("number of additional ray items (4.7.1.14)");
  if (n_extra < 0 || n_extra > kMaxExtraItems)
    throw InputError(path, "number of additional ray items (4.7.1.14)",
                     "0 to " + std::to_string(kMaxExtraItems), std::to_string(n_extra));
  const int32_t text_bytes = f.Value<int32_t>("size of the additional text block (4.7.1.15)");
  if (text_bytes < 0 || text_bytes % 32 != 0)
    throw InputError(path, "size of the additional text block (4.7.1.15)", "a multiple of 32 >= 0",
                     std::to_string(text_bytes));
  char reserved[168];
  f.Bytes(reserved, sizeof reserved, "reserved (4.7.1.16)");
  if (f.Value<int32_t>("position flag (4.7.2.1)") != 1)
    throw InputError(path, "position flag (4.7.2.1)", "1", "another value");
  if (f.Value<int32_t>("direction flag (4.7.2.2)") != 1)
    throw InputError(path, "direction flag (4.7.2.2)", "1", "another value");
  const bool radiant = f.Flag("radiant flux flag (4.7.2.3)");
  const bool wavelength = f.Flag("wavelength flag (4.7.2.4)");
  const bool luminous = f.Flag("luminous flux flag (4.7.2.5)");
  const bool stokes = f.Flag("Stokes flag (4.7.2.6)");
  const bool tristimulus = f.Flag("tristimulus flag (4.7.2.7)");
  const bool spectrum_index = f.Flag("spectrum index flag (4.7.2.8)");
  if (!radiant && !luminous)
    throw InputError(path, "flux flags (4.7.2.3, 4.7.2.5)", "a radiant or a luminous flux column",
                     "neither");
  std::string* text[] = {
      &set.name,          &set.manufacturer, &set.model_creator,          &set.rayfile_creator,
      &set.equipment,     &set.camera,       &set.light_source_operation, &set.additional_info,
      &set.data_reference};
  for (int k = 0; k < 9; ++k)
    *text[k] = f.Text(kTextChars, "description field 4.7.3." + std::to_string(k + 1));
  uint64_t table_bytes = 0;
  for (int t = 0; t < n_spectra; ++t) {
    const std::string field = "spectral table " + std::to_string(t + 1) + " (4.7.4)";
    const int32_t pairs = f.Value<int32_t>(field);
    if (pairs <= 0 || uint64_t(pairs) * 8 > f.Left())
      throw InputError(path, field, "a number of pairs > 0 within the file", std::to_string(pairs));
    f.Skip(uint64_t(pairs) * 8, field);
    table_bytes += 4 + uint64_t(pairs) * 8;
  }
  if (table_bytes % 32) f.Skip(32 - table_bytes % 32, "spectral table padding (4.7.4)");
  for (int k = 0; k < n_extra; ++k)
    f.Skip(kColumnNameBytes, "additional column name " + std::to_string(k + 1) + " (4.7.5)");
  f.Skip(uint64_t(text_bytes), "additional text block (4.7.6)");
  // Ray columns in the standard's order.
  const int items =
      6 + radiant + wavelength + luminous + 3 * stokes + 2 * tristimulus + spectrum_index + n_extra;
  const int flux_column = luminous ? 6 + radiant + wavelength : 6;
  set.photometric = luminous;
  const uint64_t ray_bytes = uint64_t(items) * 4;
  if (n_rays > f.Left() / ray_bytes || n_rays * ray_bytes != f.Left())
    throw BadInput(path + ": number of rays (4.7.1.6): the header says " + std::to_string(n_rays) +
                   " rays of " + std::to_string(items) + " values, the file holds " +
                   std::to_string(f.Left()) + " bytes of ray data (" +
                   std::to_string(f.Left() / ray_bytes) + " rays" +
                   (f.Left() % ray_bytes ? " and a partial one" : "") + ")");
  set.rays.resize(n_rays);
  std::vector<float> v(items);
  for (uint64_t r = 0; r < n_rays; ++r) {
    f.Bytes(v.data(), ray_bytes, "ray " + std::to_string(r));
    for (int k = 0; k < items; ++k)
      if (!std::isfinite(v[k]))
        throw BadInput(path + ": ray " + std::to_string(r) + ", value " + std::to_string(k + 1) +
                       ": expected a finite number, got " + Num(v[k], 8));
    const double norm = std::sqrt(double(v[3]) * v[3] + double(v[4]) * v[4] + double(v[5]) * v[5]);
    if (!(norm > 0.5 && norm < 1.5))
      throw BadInput(path + ": ray " + std::to_string(r) + ": direction (kx, ky, kz): expected " +
                     "a unit vector, got one of length " + Num(norm, 6));
    if (v[flux_column] < 0)
      throw BadInput(path + ": ray " + std::to_string(r) + ": flux: expected a number >= 0, got " +
                     Num(v[flux_column], 8));
    set.rays[r] = {
        v[0],          v[1], v[2], float(v[3] / norm), float(v[4] / norm), float(v[5] / norm),
        v[flux_column]};
  }
  return set;
}

void WriteTm25(const Tm25RaySet& set, const std::string& path) {
  if (!LittleEndian()) throw Failure("TM-25 files are little-endian; this machine is not");
  std::string out;
  out.reserve(kTm25FixedHeaderBytes + set.rays.size() * 28);
  PutBytes(&out, "TM25", 4);
  Put<int32_t>(&out, kTm25Version);
  Put<int32_t>(&out, set.creation_method);
  Put<float>(&out, float(set.luminous_flux_lm));
  Put<float>(&out, float(set.radiant_flux_w));
  Put<uint64_t>(&out, set.rays.size());
  char date[28] = {};
  std::memcpy(date, set.date_time.data(), std::min<size_t>(28, set.date_time.size()));
  PutBytes(&out, date, 28);
  Put<int32_t>(&out, 0);                              // ray start position: unspecified
  Put<int32_t>(&out, 0);                              // spectral data identifier: none
  for (int k = 0; k < 3; ++k) Put<float>(&out, 0.f);  // wavelengths: none
  Put<int32_t>(&out, 0);                              // spectral tables
  Put<int32_t>(&out, 0);                              // additional ray items
  Put<int32_t>(&out, 0);                              // additional text block bytes
  out.append(168, '\0');                              // reserved
  const int32_t flags[8] = {1, 1, set.photometric ? 0 : 1, 0, set.photometric ? 1 : 0, 0, 0, 0};
  for (int32_t flag : flags) Put<int32_t>(&out, flag);
  for (const std::string* s :
       {&set.name, &set.manufacturer, &set.model_creator, &set.rayfile_creator, &set.equipment,
        &set.camera, &set.light_source_operation, &set.additional_info, &set.data_reference})
    PutText(&out, *s, kTextChars);
  LUMISLAB_CHECK(out.size() == kTm25FixedHeaderBytes, "TM-25 header size");
  for (const Tm25Ray& r : set.rays) {
    const float v[7] = {r.x, r.y, r.z, r.kx, r.ky, r.kz, r.flux};
    PutBytes(&out, v, sizeof v);
  }
  WriteAtomically(path, [&](const std::string& tmp) {
    std::ofstream o(tmp, std::ios::binary);
    o.write(out.data(), std::streamsize(out.size()));
    o.close();
    if (!o) throw IoError(path, "cannot write");  // the output's name, not the temporary's
  });
}

}  // namespace lumislab
