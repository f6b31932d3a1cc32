#include "lib/photometry/file_info.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/input_file.h"
#include "core/log.h"
#include "lib/photometry/ies.h"
#include "lib/photometry/intensity_distribution.h"
#include "lib/photometry/tm25.h"

namespace lumislab {
namespace {

nlohmann::json NumberOrNull(double v) { return std::isfinite(v) ? nlohmann::json(v) : nullptr; }

}  // namespace

bool IsTm25File(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[4] = {};
  in.read(magic, 4);
  return in && std::string(magic, 4) == "TM25";
}

nlohmann::json PhotometricFileInfo(const std::string& path) {
  CheckInputFile(path, "file");
  nlohmann::json j;
  j["file"] = path;
  if (IsTm25File(path)) {
    const Tm25RaySet set = ReadTm25(path);
    j["format"] = "TM-25";
    j["photometric"] = set.photometric;
    j["flux_unit"] = set.photometric ? "lm" : "W";
    j["flux"] = set.FluxSum();
    j["rays"] = set.rays.size();
    j["header_luminous_flux_lm"] = NumberOrNull(set.luminous_flux_lm);
    j["header_radiant_flux_w"] = NumberOrNull(set.radiant_flux_w);
    j["date_time"] = set.date_time;
    j["name"] = set.name;
    j["manufacturer"] = set.manufacturer;
    j["rayfile_creator"] = set.rayfile_creator;
    j["additional_info"] = set.additional_info;
    // lumislab's ray files state their coverage in additional_info ("coverage: ...").
    const size_t at = set.additional_info.find("coverage: ");
    if (at != std::string::npos) j["coverage"] = set.additional_info.substr(at + 10);
    return j;
  }
  const IntensityDistribution d = ReadIntensityFile(path);
  j["format"] = d.format;
  j["photometric"] = d.photometric;
  j["intensity_unit"] = d.photometric ? "cd" : "W/sr";
  j["flux_unit"] = d.photometric ? "lm" : "W";
  j["flux"] = d.TotalFlux();  // finite: Check
  j["symmetry"] = CSymmetryName(d.Symmetry());
  j["c_planes"] = {{"count", d.c_deg.size()}, {"first", d.c_deg.front()}, {"last", d.c_deg.back()}};
  j["gamma_angles"] = {
      {"count", d.gamma_deg.size()}, {"first", d.gamma_deg.front()}, {"last", d.gamma_deg.back()}};
  size_t peak = 0;
  for (size_t k = 0; k < d.values.size(); ++k)
    if (d.values[k] > d.values[peak]) peak = k;
  j["peak"] = {{"intensity", d.values[peak]},
               {"c_deg", d.c_deg[peak / d.gamma_deg.size()]},
               {"gamma_deg", d.gamma_deg[peak % d.gamma_deg.size()]}};
  j["opening_mm"] = {{"width", d.opening.width_mm},
                     {"length", d.opening.length_mm},
                     {"height", d.opening.height_mm}};
  j["input_watts"] = d.input_watts;
  // lm/W (W/W radiometric) when the file gives the input power.
  j["efficacy"] = d.input_watts > 0 ? nlohmann::json(d.TotalFlux() / d.input_watts) : nullptr;
  if (!d.lamps.empty()) j["lamps"] = d.lamps;
  if (!d.file_generation_type.empty() && d.format == "IES LM-63-2019")
    j["file_generation_type"] = {{"code", d.file_generation_type},
                                 {"meaning", FileGenerationTypeName(d.file_generation_type)}};
  nlohmann::json keywords = nlohmann::json::object();
  for (const auto& [key, value] : d.keywords)
    if (!key.empty()) keywords[key] = value;
  j["keywords"] = keywords;
  // Coverage as lumislab states it: IES [_COVERAGE]; EULUMDAT the measurement report field
  // (line 8, read as TEST) from "partial g<=" (export/coverage.h Coverage::Short).
  if (!d.Keyword("_COVERAGE").empty()) {
    std::string text = d.Keyword("_COVERAGE");  // its [MORE] lines are one sentence
    std::replace(text.begin(), text.end(), '\n', ' ');
    j["coverage"] = text;
  } else {
    const std::string test = d.Keyword("TEST");
    const size_t at = test.find("partial g<=");
    if (at != std::string::npos) j["coverage"] = test.substr(at);
  }
  return j;
}

std::string FormatPhotometricFileInfo(const nlohmann::json& j, bool json) {
  // A file's text fields (IES keywords, the first line, a TM-25 date) are bytes, not
  // necessarily UTF-8: replaced in the JSON (U+FFFD) where nlohmann's default would throw.
  if (json) return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  std::ostringstream os;
  os << "file: " << j["file"].get<std::string>() << "\nformat: " << j["format"].get<std::string>()
     << "\n";
  const std::string unit = j["flux_unit"];
  if (j.contains("rays")) {
    os << "rays: " << j["rays"].get<size_t>() << " ("
       << (j["photometric"].get<bool>() ? "luminous" : "radiant") << " flux per ray)\n";
  } else {
    os << "symmetry: " << j["symmetry"].get<std::string>() << "\n"
       << "C planes: " << j["c_planes"]["count"].get<size_t>() << " ("
       << Num(j["c_planes"]["first"], 6) << " to " << Num(j["c_planes"]["last"], 6) << " deg)\n"
       << "gamma angles: " << j["gamma_angles"]["count"].get<size_t>() << " ("
       << Num(j["gamma_angles"]["first"], 6) << " to " << Num(j["gamma_angles"]["last"], 6)
       << " deg)\n"
       << "peak: " << Num(j["peak"]["intensity"], 6) << " "
       << j["intensity_unit"].get<std::string>() << " at C " << Num(j["peak"]["c_deg"], 6)
       << ", gamma " << Num(j["peak"]["gamma_deg"], 6) << "\n";
    if (j.contains("lamps")) os << "lamps: " << j["lamps"].get<std::string>() << "\n";
    if (j.contains("file_generation_type"))
      os << "file generation type: " << j["file_generation_type"]["code"].get<std::string>() << " ("
         << j["file_generation_type"]["meaning"].get<std::string>() << ")\n";
    for (const auto& [key, value] : j["keywords"].items()) {
      std::string text = value.get<std::string>();
      std::replace(text.begin(), text.end(), '\n', ' ');
      const std::string head = Utf8Head(text, 90);  // no character split
      os << "[" << key << "] " << head << (head.size() < text.size() ? "..." : "") << "\n";
    }
  }
  if (j.contains("coverage")) os << "coverage: " << j["coverage"].get<std::string>() << "\n";
  if (j.contains("input_watts") && j["input_watts"].get<double>() > 0)
    os << "input power: " << Num(j["input_watts"], 6) << " W, efficacy " << Num(j["efficacy"], 4)
       << " " << unit << "/W\n";
  os << "flux: " << Num(j["flux"], 7) << " " << unit << "\n";
  return os.str();
}

}  // namespace lumislab
