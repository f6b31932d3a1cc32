#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "study/study.h"

namespace lumislab {
namespace {

const char* kDLabel[3] = {"d", "2d", "4d"};

// CSV numbers: 6 significant digits (core/log.h's Num).
std::string Num6(double x) { return Num(x, 6); }
std::string Fixed(double x, const char* format) {
  char buf[32];
  std::snprintf(buf, sizeof buf, format, x);
  return buf;
}
std::string Percent(double x) { return Fixed(100 * x, "%.3g %%"); }
std::string CoveredPercent(double x) { return x < 0 ? "-" : Percent(x); }
std::string Seconds(double s) {
  if (s >= 3600) return Fixed(s / 3600, "%.2g h");
  if (s >= 60) return Fixed(s / 60, "%.3g min");
  return Fixed(s, "%.3g s");
}

// What sets a row apart from the base, in words (the table's "setting" column).
std::string Setting(const StudyRow& r) {
  std::ostringstream s;
  s << "h " << Num6(r.h_mm) << " mm, " << r.nu << "x" << r.nv << ", " << r.photo_w << "x"
    << r.photo_h << " px, K " << r.k_max << ", " << r.slab_res << " texels, N " << r.samples;
  if (r.full_well_e > 0) s << ", full well " << Num6(r.full_well_e) << " e-";
  if (r.brackets > 1) s << ", " << r.brackets << " brackets";
  if (r.lambda >= 0) s << ", lambda " << Num6(r.lambda);
  return s.str();
}

}  // namespace

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> out;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) out.push_back(field);
  if (!line.empty() && line.back() == ',') out.push_back("");
  return out;
}

std::string StudyCsvHeader() {
  return "knob,value,key,h_mm,nu,nv,positions,photo_w,photo_h,k_max,slab_res,samples,render_px,"
         "full_well_e,brackets,lambda,"
         "slab_rel_l2,err_d,flux_d,err_2d,flux_2d,err_4d,flux_4d,err_cov_d,covered_d,err_cov_2d,"
         "covered_2d,err_cov_4d,covered_4d,lab_s,acquire_s,calibrate_s,reconstruct_s,render_s,"
         "total_s,preview_ms";
}

std::string StudyCsvLine(const StudyRow& r) {
  std::ostringstream s;
  s << r.knob << "," << r.value << "," << r.key << "," << Num6(r.h_mm) << "," << r.nu << "," << r.nv
    << "," << r.positions() << "," << r.photo_w << "," << r.photo_h << "," << r.k_max << ","
    << r.slab_res << "," << r.samples << "," << r.render_px << "," << Num6(r.full_well_e) << ","
    << r.brackets << "," << Num6(r.lambda) << "," << Num6(r.slab_rel_l2);
  for (int k = 0; k < 3; ++k) s << "," << Num6(r.err[k]) << "," << Num6(r.flux[k]);
  for (int k = 0; k < 3; ++k) s << "," << Num6(r.err_covered[k]) << "," << Num6(r.covered[k]);
  s << "," << Num6(r.lab_s) << "," << Num6(r.acquire_s) << "," << Num6(r.calibrate_s) << ","
    << Num6(r.reconstruct_s) << "," << Num6(r.render_s) << "," << Num6(r.total_s) << ","
    << Num6(r.preview_ms);
  return s.str();
}

void ReadCsvLines(const std::string& path, const std::string& header, size_t fields,
                  const std::function<void(const std::vector<std::string>&)>& parse) {
  std::istringstream in(ReadTextFile(path));
  std::string line;
  if (!std::getline(in, line) || line != header)
    throw BadInput(path + ": line 1: expected the header of lumislab-study's CSV, got \"" +
                   line.substr(0, 60) + "\"");
  for (int number = 2; std::getline(in, line); ++number) {
    if (line.empty()) continue;
    const std::vector<std::string> f = SplitCsvLine(line);
    const std::string where = path + ": line " + std::to_string(number) + ": ";
    if (f.size() != fields)
      throw BadInput(where + "expected " + std::to_string(fields) + " fields, got " +
                     std::to_string(f.size()));
    try {
      parse(f);
    } catch (const std::exception&) {
      throw BadInput(where + "a field is not a number");
    }
  }
}

std::vector<StudyRow> ReadStudyCsv(const std::string& path) {
  std::vector<StudyRow> rows;
  ReadCsvLines(path, StudyCsvHeader(), 36, [&](const std::vector<std::string>& f) {
    StudyRow r;
    size_t i = 0;
    r.knob = f[i++], r.value = f[i++], r.key = f[i++];
    r.h_mm = std::stod(f[i++]);
    r.nu = std::stoi(f[i++]), r.nv = std::stoi(f[i++]);
    ++i;  // positions = nu * nv
    r.photo_w = std::stoi(f[i++]), r.photo_h = std::stoi(f[i++]);
    r.k_max = std::stoi(f[i++]), r.slab_res = std::stoi(f[i++]);
    r.samples = std::stoi(f[i++]), r.render_px = std::stoi(f[i++]);
    r.full_well_e = std::stod(f[i++]), r.brackets = std::stoi(f[i++]);
    r.lambda = std::stod(f[i++]);
    r.slab_rel_l2 = std::stod(f[i++]);
    for (int k = 0; k < 3; ++k) r.err[k] = std::stod(f[i++]), r.flux[k] = std::stod(f[i++]);
    for (int k = 0; k < 3; ++k)
      r.err_covered[k] = std::stod(f[i++]), r.covered[k] = std::stod(f[i++]);
    r.lab_s = std::stod(f[i++]), r.acquire_s = std::stod(f[i++]);
    r.calibrate_s = std::stod(f[i++]), r.reconstruct_s = std::stod(f[i++]);
    r.render_s = std::stod(f[i++]), r.total_s = std::stod(f[i++]);
    r.preview_ms = std::stod(f[i++]);
    rows.push_back(r);
  });
  return rows;
}

std::vector<size_t> ParetoFront(const std::vector<StudyRow>& rows, int d_index) {
  std::vector<size_t> unique;
  std::set<std::string> keys;
  for (size_t i = 0; i < rows.size(); ++i)
    if (keys.insert(rows[i].key).second) unique.push_back(i);
  const auto dominates = [&](const StudyRow& a, const StudyRow& b) {
    const double ea = a.err[d_index], eb = b.err[d_index];
    return (ea < eb && a.total_s <= b.total_s * (1 + kTimeScatter)) ||
           (ea == eb && a.total_s < b.total_s);
  };
  std::vector<size_t> front;
  for (size_t i : unique)
    if (std::none_of(unique.begin(), unique.end(),
                     [&](size_t j) { return j != i && dominates(rows[j], rows[i]); }))
      front.push_back(i);
  std::sort(front.begin(), front.end(), [&](size_t a, size_t b) {
    if (rows[a].total_s != rows[b].total_s) return rows[a].total_s < rows[b].total_s;
    return rows[a].err[d_index] < rows[b].err[d_index];
  });
  return front;
}

std::string ParetoTables(const std::vector<StudyRow>& rows) {
  std::ostringstream s;
  for (int d : {0, 2}) {
    s << "Pareto front, relative L2 error at D = " << kDLabel[d] << " against total time:\n\n"
      << "| error at " << kDLabel[d] << " | total | lab | reconstruct | render | preview frame | "
      << "knob = value | setting |\n|---|---|---|---|---|---|---|---|\n";
    for (size_t i : ParetoFront(rows, d)) {
      const StudyRow& r = rows[i];
      s << "| " << Percent(r.err[d]) << " | " << Seconds(r.total_s) << " | " << Seconds(r.lab_s)
        << " | " << Seconds(r.reconstruct_s) << " | " << Seconds(r.render_s) << " | "
        << Fixed(r.preview_ms, "%.3g ms") << " | " << r.knob << " = " << r.value << " | "
        << Setting(r) << " |\n";
    }
    s << "\n";
  }
  return s.str();
}

std::string TargetTable(const std::vector<StudyRow>& rows) {
  std::ostringstream s;
  s << "Cheapest measured setting per target (least total time with the error at D within the "
       "target):\n\n"
    << "| target | D | error | total | lab | reconstruct | render | preview frame | knob = value "
       "| setting |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (int d : {0, 2})
    for (double target : {0.05, 0.02, 0.01, 0.005}) {
      const StudyRow* fastest = nullptr;
      for (const StudyRow& r : rows)
        if (r.err[d] <= target && (!fastest || r.total_s < fastest->total_s)) fastest = &r;
      const StudyRow* best = fastest;  // the most accurate as fast within the scatter
      for (const StudyRow& r : rows)
        if (fastest && r.err[d] <= target && r.total_s <= fastest->total_s * (1 + kTimeScatter) &&
            r.err[d] < best->err[d])
          best = &r;
      s << "| " << Percent(target) << " | " << kDLabel[d] << " | ";
      if (!best) {
        s << "none measured | | | | | | | |\n";
        continue;
      }
      const StudyRow& r = *best;
      s << Percent(r.err[d]) << " | " << Seconds(r.total_s) << " | " << Seconds(r.lab_s) << " | "
        << Seconds(r.reconstruct_s) << " | " << Seconds(r.render_s) << " | "
        << Fixed(r.preview_ms, "%.3g ms") << " | " << r.knob << " = " << r.value << " | "
        << Setting(r) << " |\n";
    }
  return s.str() + "\n";
}

std::string StudyReport(const std::vector<StudyRow>& rows,
                        const std::vector<std::string>& knob_order, const std::string& header) {
  std::ostringstream s;
  s << header << "\n";
  for (const std::string& knob : knob_order) {
    bool any = false;
    for (const StudyRow& r : rows) any |= r.knob == knob;
    if (!any) continue;
    s << "## Knob `" << knob << "`\n\n"
      << "| value | positions | setting | slab vs truth | err d | err 2d | err 4d | flux d | "
         "flux 4d | covered d | err d covered | err 4d covered | lab | acquire (sim) | "
         "reconstruct | render | total | preview frame |\n"
      << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const StudyRow& r : rows) {
      if (r.knob != knob) continue;
      s << "| " << r.value << " | " << r.positions() << " | " << Setting(r) << " | "
        << Percent(r.slab_rel_l2) << " | " << Percent(r.err[0]) << " | " << Percent(r.err[1])
        << " | " << Percent(r.err[2]) << " | " << Fixed(r.flux[0], "%.4f") << " | "
        << Fixed(r.flux[2], "%.4f") << " | " << Percent(r.covered[0]) << " | "
        << CoveredPercent(r.err_covered[0]) << " | " << CoveredPercent(r.err_covered[2]) << " | "
        << Seconds(r.lab_s) << " | " << Seconds(r.acquire_s) << " | " << Seconds(r.reconstruct_s)
        << " | " << Seconds(r.render_s) << " | " << Seconds(r.total_s) << " | "
        << Fixed(r.preview_ms, "%.3g ms") << " |\n";
    }
    s << "\n";
  }
  s << "## Pareto fronts\n\n" << ParetoTables(rows) << TargetTable(rows);
  s << "Plots: `study_d.svg`, `study_4d.svg` (error against total time, log axes, one curve per "
       "knob, the front in red).\n";
  return s.str();
}

std::string StudySvg(const std::vector<StudyRow>& rows, const std::vector<std::string>& knob_order,
                     int d_index) {
  const double kW = 720, kH = 480, kL = 80, kR = 170, kT = 40, kB = 60;
  const double floor_err = 1e-7;  // an error of 0 is drawn at the bottom of a log axis
  double t0 = INFINITY, t1 = -INFINITY, e0 = INFINITY, e1 = -INFINITY;
  for (const StudyRow& r : rows) {
    const double e = std::max(r.err[d_index], floor_err), t = std::max(r.total_s, 1e-3);
    t0 = std::min(t0, t), t1 = std::max(t1, t), e0 = std::min(e0, e), e1 = std::max(e1, e);
  }
  if (rows.empty()) t0 = 1, t1 = 10, e0 = 1e-3, e1 = 1e-2;
  // Whole decades around the data.
  const double lt0 = std::floor(std::log10(t0)), lt1 = std::max(std::ceil(std::log10(t1)), lt0 + 1);
  const double le0 = std::floor(std::log10(e0)), le1 = std::max(std::ceil(std::log10(e1)), le0 + 1);
  const auto X = [&](double t) {
    return kL + (std::log10(std::max(t, 1e-3)) - lt0) / (lt1 - lt0) * (kW - kL - kR);
  };
  const auto Y = [&](double e) {
    return kH - kB - (std::log10(std::max(e, floor_err)) - le0) / (le1 - le0) * (kH - kT - kB);
  };
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << kW << "\" height=\"" << kH
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
    << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    << "<text x=\"" << kL << "\" y=\"24\" font-size=\"14\">relative L2 error of the receiver-plane "
    << "irradiance at D = " << kDLabel[d_index] << " against total time</text>\n";
  for (double p = lt0; p <= lt1; ++p)
    s << "<line x1=\"" << X(std::pow(10, p)) << "\" y1=\"" << kT << "\" x2=\"" << X(std::pow(10, p))
      << "\" y2=\"" << kH - kB << "\" stroke=\"#ddd\"/><text x=\"" << X(std::pow(10, p))
      << "\" y=\"" << kH - kB + 16 << "\" text-anchor=\"middle\">1e" << p << " s</text>\n";
  for (double p = le0; p <= le1; ++p)
    s << "<line x1=\"" << kL << "\" y1=\"" << Y(std::pow(10, p)) << "\" x2=\"" << kW - kR
      << "\" y2=\"" << Y(std::pow(10, p)) << "\" stroke=\"#ddd\"/><text x=\"" << kL - 6 << "\" y=\""
      << Y(std::pow(10, p)) + 4 << "\" text-anchor=\"end\">1e" << p << "</text>\n";
  s << "<text x=\"" << (kL + kW - kR) / 2 << "\" y=\"" << kH - 18
    << "\" text-anchor=\"middle\">total time (lab model + reconstruct + render), s</text>\n";
  const char* colours[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd",
                           "#8c564b", "#e377c2", "#17becf", "#7f7f7f"};
  int c = 0;
  for (const std::string& knob : knob_order) {
    std::vector<const StudyRow*> curve;
    for (const StudyRow& r : rows)
      if (r.knob == knob) curve.push_back(&r);
    if (curve.empty()) continue;
    const char* colour = colours[c % 8];
    s << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"1.5\" points=\"";
    for (const StudyRow* r : curve) s << X(r->total_s) << "," << Y(r->err[d_index]) << " ";
    s << "\"/>\n";
    for (const StudyRow* r : curve)
      s << "<circle cx=\"" << X(r->total_s) << "\" cy=\"" << Y(r->err[d_index])
        << "\" r=\"3\" fill=\"" << colour << "\"><title>" << knob << " = " << r->value
        << "</title></circle>\n";
    s << "<text x=\"" << kW - kR + 10 << "\" y=\"" << kT + 16 * (c + 1) << "\" fill=\"" << colour
      << "\">" << knob << "</text>\n";
    ++c;
  }
  // The front: a red staircase through its points, each ringed.
  const std::vector<size_t> front = ParetoFront(rows, d_index);
  s << "<polyline fill=\"none\" stroke=\"red\" stroke-dasharray=\"4 3\" points=\"";
  for (size_t k = 0; k < front.size(); ++k) {
    const StudyRow& r = rows[front[k]];
    if (k > 0) s << X(r.total_s) << "," << Y(rows[front[k - 1]].err[d_index]) << " ";
    s << X(r.total_s) << "," << Y(r.err[d_index]) << " ";
  }
  s << "\"/>\n";
  for (size_t i : front)
    s << "<circle cx=\"" << X(rows[i].total_s) << "\" cy=\"" << Y(rows[i].err[d_index])
      << "\" r=\"6\" fill=\"none\" stroke=\"red\" stroke-width=\"1.5\"/>\n";
  s << "<text x=\"" << kW - kR + 10 << "\" y=\"" << kT + 16 * (c + 2)
    << "\" fill=\"red\">Pareto front</text>\n</svg>\n";
  return s.str();
}

}  // namespace lumislab
