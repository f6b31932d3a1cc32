// The lab report's HTML (export/report.h): one self-contained document, inline SVG diagrams and
// PNG plane pictures, CSS for A4 print. Directions are labelled by C as the far field gives them.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/geometry.h"
#include "core/log.h"
#include "export/report.h"
#include "export/report_svg.h"
#include "lib/lightfield/false_colour.h"
#include "lib/lightfield/polar_plot.h"

namespace lumislab {
namespace {

const char* const kPairColours[] = {"#c81e1e", "#1e46c8", "#1b8a3a", "#a0522d"};

const char kCss[] = R"(
@page { size: A4; margin: 14mm 13mm; }
body { font-family: "DejaVu Sans", "Liberation Sans", Arial, sans-serif; font-size: 10pt;
       color: #222; max-width: 186mm; margin: 0 auto; }
h1 { font-size: 17pt; margin: 0 0 2mm; }
h2 { font-size: 12.5pt; border-bottom: 1px solid #999; margin: 6mm 0 2mm; }
section { break-inside: avoid; page-break-inside: avoid; }
.page { break-before: page; page-break-before: always; }
table { border-collapse: collapse; margin: 1mm 0 2mm; }
td, th { border: 1px solid #bbb; padding: 1px 5px; text-align: right; }
th { background: #eee; }
td.l, th.l { text-align: left; }
table.candela td, table.candela th { font-size: 7.5pt; padding: 0 3px; }
.note { color: #555; font-size: 8.5pt; }
.warn { color: #8a3b00; }
.figs { display: flex; flex-wrap: wrap; gap: 4mm; }
figure { margin: 0; }
figcaption { font-size: 8.5pt; color: #444; max-width: 90mm; }
)";

struct Page {
  const ReportData& r;
  std::ostringstream html;
  double Scale(double intensity) const {
    return r.per_klm && r.distribution.photometric ? r.summary.PerKlm(intensity) : intensity;
  }
};

// An edge of the pair's spread, or why there is none: beyond the seen cone it is unknown; with
// every direction to gamma 180 seen (a luminaire folder's sphere) the light never falls to the
// level there.
std::string SpreadText(const ReportData& r, double angle, double at_least, const char* level) {
  if (std::isfinite(angle)) return Deg(angle);
  if (r.seen_cone_deg >= 180 - 1e-6)
    return std::string("none (above ") + level + " of the peak to &gamma; 180&deg;)";
  return "&gt; " + Deg(at_least) + " (edge not seen)";
}

std::string PairName(double c) { return "C" + Num(c, 4) + "\u2013C" + Num(c + 180, 4); }

void Summary(Page& p) {
  const ReportData& r = p.r;
  const PhotometricSummary& s = r.summary;
  const std::string flux = r.FluxUnit(), cd = r.distribution.photometric ? "cd" : "W/sr";
  auto& h = p.html;
  h << "<section><h2>Summary</h2><table>\n";
  auto row = [&](const std::string& k, const std::string& v) {
    h << "<tr><th class=l>" << k << "</th><td class=l>" << v << "</td></tr>\n";
  };
  row("Total flux (seen directions)", Fmt(s.total_flux, 5) + " " + flux + " &plusmn; " +
                                          Num(100 * r.uncertainty.FluxExpanded(), 2) +
                                          " % (k = 2)");
  row("Flux in the measured cone", Fmt(r.flux_in_cone, 5) + " " + flux + " within &gamma; &le; " +
                                       Deg(r.seen_cone_deg) + " (every C seen there)");
  row("Coverage", Num(100 * r.seen_fraction, 3) + " % of the " + r.Domain() +
                      "'s solid angle seen; directions beyond are unknown, not dark");
  row("Peak intensity", Fmt(s.peak, 5) + " " + cd + " at C " + Deg(s.peak_c_deg) + ", &gamma; " +
                            Deg(s.peak_gamma_deg) + " &plusmn; " +
                            Num(100 * r.uncertainty.PeakExpanded(), 2) + " % (k = 2)");
  for (const BeamSpread& b : s.spreads) {
    row("Beam / field angle " + PairName(b.c_deg),
        SpreadText(r, b.beam_deg, b.beam_at_least_deg, "50 %") + " / " +
            SpreadText(r, b.field_deg, b.field_at_least_deg, "10 %") + "; NEMA type " +
            (std::isfinite(b.field_deg) && NemaBeamType(b.field_deg) > 0
                 ? std::to_string(NemaBeamType(b.field_deg))
                 : std::string("\u2014")));
  }
  if (s.spreads.size() >= 2) {
    const int h_type = NemaBeamType(s.spreads[0].field_deg),
              v_type = NemaBeamType(s.spreads[1].field_deg);
    row("NEMA beam type (FL 11)",
        h_type > 0 && v_type > 0 ? std::to_string(h_type) + "H &times; " + std::to_string(v_type) +
                                       "V (C0&ndash;C180 &times; "
                                       "C90&ndash;C270)"
                                 : "\u2014 (a field angle below 10&deg; or not seen)");
  }
  row("CIE flux code (CIE 52)",
      CieFluxCodeText(s.cie_flux_code) + " <span class=note>(N5 = 100: absolute photometry" +
          (r.seen_cone_deg < 90 - 1e-9
               ? "; from the seen directions only, the measured cone ends at &gamma; = " +
                     Deg(r.seen_cone_deg)
               : std::string()) +
          ")</span>");
  if (s.efficacy > 0 && r.seen_fraction < 1 - 1e-9)  // the unseen flux is not in it
    row("Luminous efficacy (seen flux)",
        "&ge; " + Fmt(s.efficacy, 4) + " lm/W at " + Fmt(s.input_watts, 4) +
            " W <span class=note>(a lower bound: the flux of the seen directions only, " +
            Num(100 * r.seen_fraction, 3) + " % of the " + r.Domain() + ")</span>");
  else if (s.efficacy > 0)
    row("Luminous efficacy", Fmt(s.efficacy, 4) + " lm/W at " + Fmt(s.input_watts, 4) + " W");
  else
    row("Luminous efficacy", s.input_watts > 0 ? "\u2014 (not photometric units)"
                                               : "\u2014 (input power not given: --input-watts)");
  h << "</table>\n";
  if (!r.distribution.photometric)
    h << "<p class=\"note warn\">The slab is in " << XmlEscape(r.info.units)
      << " units: intensities are W/sr and fluxes W (radiometric). Calibrate the scale with a lux "
         "meter (lumislab-calibrate scale --unit lux) for cd and lm." +
             std::string(r.per_klm ? " --per-klm is ignored: cd/klm needs lm." : "") + "</p>\n";
  h << "</section>\n";
}

// Beam and field angles of every C-plane pair the grid stores, every 15 degrees (or the grid's
// step when coarser).
void SpreadTable(Page& p) {
  const ReportData& r = p.r;
  const IntensityDistribution& d = r.distribution;
  const double step = std::max(15.0, d.c_deg[1] - d.c_deg[0]);
  auto& h = p.html;
  h << "<section><h2>Beam and field angles per C-plane pair</h2><table><tr><th "
       "class=l>pair</th><th>peak ("
    << r.IntensityUnit() << ")</th><th>beam (50 %)</th><th>field (10 %)</th><th>NEMA</th></tr>\n";
  for (double c = 0; c < 180 - 1e-9; c += step) {
    BeamSpread b;
    if (!BeamSpreadOfPair(d, r.seen, c, &b)) continue;
    const int nema = NemaBeamType(b.field_deg);
    h << "<tr><td class=l>" << PairName(c) << "</td><td>" << Fmt(p.Scale(b.peak), 4) << "</td><td>"
      << SpreadText(p.r, b.beam_deg, b.beam_at_least_deg, "50 %") << "</td><td>"
      << SpreadText(p.r, b.field_deg, b.field_at_least_deg, "10 %") << "</td><td>"
      << (nema > 0 ? std::to_string(nema) : "\u2014") << "</td></tr>\n";
  }
  h << "</table><p class=note>Edges: the first crossing of 50 % and 10 % of the pair's peak "
       "going outwards from it, linear in &gamma; between grid angles.</p></section>\n";
}

void Zonal(Page& p) {
  const ReportData& r = p.r;
  auto& h = p.html;
  h << "<section><h2>Zonal lumens</h2><table><tr><th>zone &gamma;</th><th>flux (" << r.FluxUnit()
    << ")</th><th>% of total</th><th>cumulative %</th></tr>\n";
  double cumulative = 0;
  for (const ZonalFlux& z : r.summary.zones) {
    cumulative += z.percent;
    const bool unseen = z.gamma_hi_deg > r.seen_cone_deg + 1e-9;
    h << "<tr><td>" << Num(z.gamma_lo_deg, 3) << "&ndash;" << Num(z.gamma_hi_deg, 3)
      << "&deg;</td><td>" << Fmt(z.flux, 4) << (unseen ? " *" : "") << "</td><td>"
      << Fmt(z.percent, 3) << "</td><td>" << Fmt(cumulative, 4) << "</td></tr>\n";
  }
  h << "</table><p class=note>* the zone reaches beyond the measured cone (&gamma; &le; "
    << Deg(r.seen_cone_deg) << "): its unseen directions count 0.</p></section>\n";
}

// The seen part of plane C's profile (0 beyond), scaled to the report's unit.
std::vector<double> PlaneCurve(const Page& p, double c, size_t n) {
  const IntensityDistribution& d = p.r.distribution;
  const int plane = d.StoredPlane(c);
  std::vector<double> out;
  if (plane < 0) return out;
  for (size_t ig = 0; ig < n; ++ig) out.push_back(p.Scale(d.At(plane, ig)));
  return out;
}

void Polar(Page& p) {
  const ReportData& r = p.r;
  const IntensityDistribution& d = r.distribution;
  size_t n = 0;
  while (n < d.gamma_deg.size() && d.gamma_deg[n] <= r.seen_cone_deg + 1e-9) ++n;
  if (n < 2) {
    p.html << "<section><h2>Polar diagram</h2><p>Too few directions seen.</p></section>\n";
    return;
  }
  PolarPlotData data;
  data.gamma_deg.assign(d.gamma_deg.begin(), d.gamma_deg.begin() + n);
  data.c0 = PlaneCurve(p, 0, n);
  data.c180 = PlaneCurve(p, 180, n);
  data.c90 = PlaneCurve(p, 90, n);
  data.c270 = PlaneCurve(p, 270, n);
  data.unit = r.IntensityUnit();
  data.title = "Intensity, \u03B3 = 0 to " + Deg(r.seen_cone_deg) + " (the measured cone)";
  for (const BeamSpread& b : r.summary.spreads) {
    if (b.c_deg != 0 && b.c_deg != 90) continue;
    const bool c90 = b.c_deg == 90;
    for (const auto& [angle, label] : {std::pair<double, const char*>{b.beam_lo_deg, "50%"},
                                       {b.beam_hi_deg, "50%"},
                                       {b.field_lo_deg, "10%"},
                                       {b.field_hi_deg, "10%"}})
      data.marks.push_back({angle, c90, label});
  }
  p.html << "<section><h2>Polar diagram</h2><figure>" << PolarPlotSvg(MakePolarPlot(data, 520))
         << "<figcaption>&gamma; = 0 (the luminaire's axis, +z) points down; the planes C0 and C90 "
            "to the right, C180 and C270 to the left, as the far field names them. Dashed radial "
            "lines: beam (50 % of the pair's peak) and field (10 %) edges.</figcaption></figure>"
            "</section>\n";
}

void Linear(Page& p) {
  const ReportData& r = p.r;
  const IntensityDistribution& d = r.distribution;
  SvgAxes a;
  a.width = 640;
  a.height = 260;
  a.x0 = -r.gamma_span_deg;
  a.x1 = r.gamma_span_deg;
  double top = 0;
  std::vector<std::pair<std::vector<double>, std::vector<double>>> curves;
  for (const BeamSpread& b : r.summary.spreads) {
    std::vector<double> x, y;
    const int plus = d.StoredPlane(b.c_deg), minus = d.StoredPlane(b.c_deg + 180);
    const size_t ng = d.gamma_deg.size();
    for (size_t k = ng; k-- > 1;) {
      x.push_back(-d.gamma_deg[k]);
      y.push_back(r.seen[minus * ng + k] ? p.Scale(d.At(minus, k)) : NAN);
    }
    for (size_t k = 0; k < ng; ++k) {
      x.push_back(d.gamma_deg[k]);
      y.push_back(r.seen[plus * ng + k] ? p.Scale(d.At(plus, k)) : NAN);
    }
    for (double v : y)
      if (std::isfinite(v)) top = std::max(top, v);
    curves.push_back({x, y});
  }
  a.y1 = top > 0 ? top * 1.05 : 1;
  auto& h = p.html;
  h << "<section><h2>Linear diagram</h2><figure>"
    << a.Open("signed \u03B3 (\u00B0): \u2212 in plane C + 180, + in plane C",
              "I (" + r.IntensityUnit() + ")");
  for (size_t k = 0; k < curves.size(); ++k) {
    const BeamSpread& b = r.summary.spreads[k];
    h << a.Polyline(curves[k].first, curves[k].second, kPairColours[k % 4], 1.6);
    for (double e : {b.beam_lo_deg, b.beam_hi_deg, b.field_lo_deg, b.field_hi_deg})
      if (std::isfinite(e))
        h << "<line x1=\"" << a.X(e) << "\" y1=\"" << a.top << "\" x2=\"" << a.X(e) << "\" y2=\""
          << a.height - a.bottom << "\" stroke=\"" << kPairColours[k % 4]
          << "\" stroke-dasharray=\"3,3\" stroke-width=\"0.8\"/>\n";
    h << "<text x=\"" << a.left + 8 << "\" y=\"" << a.top + 14 + 13 * k << "\" fill=\""
      << kPairColours[k % 4] << "\">" << PairName(b.c_deg) << "</text>\n";
  }
  h << "</svg><figcaption>Intensity across each C-plane pair; gaps: directions not seen. Dashed: "
       "beam (50 %) and field (10 %) edges.</figcaption></figure></section>\n";
}

void IsoCandela(Page& p) {
  const ReportData& r = p.r;
  const IntensityDistribution& d = r.distribution;
  const double size = 420, cx = size / 2, cy = size / 2, R = size / 2 - 34;
  const int nc = int(d.c_deg.size()), ng = int(d.gamma_deg.size());
  // Page position of (C, gamma): gamma radially (R at the grid's last gamma, 90 or 180 degrees),
  // C counter-clockwise from the right.
  const double span = r.gamma_span_deg;
  auto at = [&](double c_deg, double g_deg) {
    const double rr = g_deg / span * R, c = c_deg * kPi / 180;
    return std::make_pair(cx + rr * std::cos(c), cy - rr * std::sin(c));
  };
  auto grid_at = [&](double fx, double fy) {
    const int ix = std::min(int(fx), nc - 2), iy = std::min(int(fy), ng - 2);
    const double c = d.c_deg[ix] + (fx - ix) * (d.c_deg[ix + 1] - d.c_deg[ix]);
    const double g = d.gamma_deg[iy] + (fy - iy) * (d.gamma_deg[iy + 1] - d.gamma_deg[iy]);
    return at(c, g);
  };
  std::vector<double> v(size_t(nc) * ng);  // rows along gamma, columns along C
  std::vector<uint8_t> valid(v.size());
  for (int ic = 0; ic < nc; ++ic)
    for (int ig = 0; ig < ng; ++ig) {
      v[size_t(ig) * nc + ic] = d.At(ic, ig);
      valid[size_t(ig) * nc + ic] = r.seen[size_t(ic) * ng + ig];
    }
  auto& h = p.html;
  h << "<section><h2>Iso-candela diagram</h2><figure><svg xmlns=\"http://www.w3.org/2000/svg\" "
       "width=\""
    << size << "\" height=\"" << size << "\" font-family=\"sans-serif\" font-size=\"10\">\n";
  // Unseen directions shaded: one wedge per C column and run of unseen gamma.
  for (int ic = 0; ic + 1 < nc; ++ic)
    for (int ig = 0; ig < ng; ++ig) {
      if (r.seen[size_t(ic) * ng + ig]) continue;
      int end = ig;
      while (end + 1 < ng && !r.seen[size_t(ic) * ng + end + 1]) ++end;
      const double g0 = d.gamma_deg[ig], g1 = d.gamma_deg[end], c0 = d.c_deg[ic],
                   c1 = d.c_deg[ic + 1];
      const auto a = at(c0, g0), b = at(c1, g0), c = at(c1, g1), e = at(c0, g1);
      h << "<path d=\"M" << a.first << " " << a.second << "L" << b.first << " " << b.second << "L"
        << c.first << " " << c.second << "L" << e.first << " " << e.second
        << "Z\" fill=\"#e4e4e4\" stroke=\"#e4e4e4\" stroke-width=\"0.5\"/>\n";
      ig = end;
    }
  const int ring = span > 90 ? 30 : 15;
  for (int g = ring; g <= span + 1e-9; g += ring) {
    h << "<circle cx=\"" << cx << "\" cy=\"" << cy << "\" r=\"" << g / span * R
      << "\" fill=\"none\" stroke=\"#bbb\"/>\n";
    h << "<text x=\"" << cx + g / span * R + 2 << "\" y=\"" << cy - 3 << "\" fill=\"#666\">" << g
      << "\u00B0</text>\n";
  }
  for (int c = 0; c < 360; c += 30) {
    const auto e = at(c, span), t = at(c, span + 22 / R * span);
    h << "<line x1=\"" << cx << "\" y1=\"" << cy << "\" x2=\"" << e.first << "\" y2=\"" << e.second
      << "\" stroke=\"#ccc\"/><text x=\"" << t.first << "\" y=\"" << t.second + 3
      << "\" text-anchor=\"middle\">C" << c << "</text>\n";
  }
  const double peak = r.summary.peak;
  for (int pct = 10; pct <= 90; pct += 10) {
    const double hue = 240.0 * (1 - (pct - 10) / 80.0);
    h << "<path fill=\"none\" stroke=\"hsl(" << hue << ",75%,40%)\" stroke-width=\""
      << (pct == 50 || pct == 10 ? 1.8 : 1) << "\" d=\""
      << ContourPath(v, nc, ng, pct / 100.0 * peak, grid_at, valid) << "\"/>\n";
  }
  h << "</svg><figcaption>Iso-candela lines at 10 %, 20 %, &hellip; 90 % of the peak ("
    << Fmt(p.Scale(peak), 4) << " " << r.IntensityUnit()
    << "; blue 10 % to red 90 %, 10 % and 50 % bold): azimuthal map, &gamma; radially (rings "
       "every "
    << ring << "&deg;), C as labelled. Grey: not seen.</figcaption></figure></section>\n";
}

void Planes(Page& p) {
  const ReportData& r = p.r;
  auto& h = p.html;
  h << "<section class=page><h2>Illuminance on planes</h2><div class=figs>\n";
  for (const ReportPlane& plane : r.planes) {
    const int n = plane.size;
    const double top = *std::max_element(plane.luminance.begin(), plane.luminance.end());
    Rgb8Image picture(n, n, {0, 0, 0});
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        picture.Set(x, y, Viridis(top > 0 ? plane.luminance[size_t(y) * n + x] / top : 0));
    SvgAxes a;
    a.width = 330;
    a.height = 300;
    a.right = 14;
    a.x0 = a.y0 = -plane.extent_mm / 2;
    a.x1 = a.y1 = plane.extent_mm / 2;
    h << "<figure>" << a.Open("x (mm)", "y (mm)");
    h << "<image x=\"" << a.X(a.x0) << "\" y=\"" << a.Y(a.y1) << "\" width=\""
      << a.X(a.x1) - a.X(a.x0) << "\" height=\"" << a.Y(a.y0) - a.Y(a.y1)
      << "\" preserveAspectRatio=\"none\" href=\"" << PngDataUri(picture) << "\"/>\n";
    // Pixel centres in mm: x right, y up (row 0 on top).
    auto page = [&](double fx, double fy) {
      const double xm = (fx + 0.5) / n * plane.extent_mm - plane.extent_mm / 2;
      const double ym = plane.extent_mm / 2 - (fy + 0.5) / n * plane.extent_mm;
      return std::make_pair(a.X(xm), a.Y(ym));
    };
    std::vector<double> values(plane.luminance.begin(), plane.luminance.end());
    h << "<path fill=\"none\" stroke=\"white\" stroke-width=\"1.4\" d=\""
      << ContourPath(values, n, n, 0.5 * top, page) << "\"/>\n";
    h << "<path fill=\"none\" stroke=\"#ff8c00\" stroke-width=\"1.4\" d=\""
      << ContourPath(values, n, n, 0.1 * top, page) << "\"/>\n";
    const double ox = a.X(0), oy = a.Y(0), arrow = 0.18 * (a.X(a.x1) - a.X(a.x0));
    h << "<g stroke=\"red\" stroke-width=\"1.5\"><line x1=\"" << ox - 6 << "\" y1=\"" << oy
      << "\" x2=\"" << ox + 6 << "\" y2=\"" << oy << "\"/><line x1=\"" << ox << "\" y1=\"" << oy - 6
      << "\" x2=\"" << ox << "\" y2=\"" << oy + 6 << "\"/></g>\n"
      << "<g stroke=\"white\" fill=\"white\"><line x1=\"" << ox + 10 << "\" y1=\"" << oy + 18
      << "\" x2=\"" << ox + 10 + arrow << "\" y2=\"" << oy + 18 << "\" stroke-width=\"1.5\"/>"
      << "<path d=\"M" << ox + 10 + arrow + 6 << " " << oy + 18 << "l-8 -4v8z\"/></g>"
      << "<text x=\"" << ox + 12 << "\" y=\"" << oy + 30 << "\" fill=\"white\">+x (C0)</text>\n";
    h << "</svg><figcaption>D = " << Num(plane.distance_mm, 5) << " mm, " << r.IlluminanceUnit()
      << ", 0 (dark) to " << Fmt(top, 4) << " (yellow), viridis. Red cross: the luminaire's axis "
      << "(x = y = 0); white line 50 %, orange 10 % of the plane's maximum. +x right, +y up: "
      << "the view from beyond the plane towards the luminaire.";
    if (!plane.note.empty()) h << " <b class=warn>Warning: " << XmlEscape(plane.note) << ".</b>";
    h << "</figcaption></figure>\n";
  }
  h << "</div></section>\n";
}

void NearField(Page& p) {
  const ReportData& r = p.r;
  auto& h = p.html;
  h << "<section><h2>Near-field advantage</h2><p>The slab gives the illuminance on a plane at "
       "any distance from the measured light field; a far-field (point source) model predicts "
       "E = I(&gamma;) cos &gamma; / r&sup2;, which is wrong near an extended luminaire.</p>"
       "<table><tr><th>D (mm)</th><th>E slab, axis (" +
           r.IlluminanceUnit() +
           ")</th><th>E far field, axis</th><th>far / slab &minus; 1</th>"
           "<th>largest |far &minus; slab| / slab max on y = 0</th></tr>\n";
  for (const ReportPlane& plane : r.planes) {
    double worst = 0, top = 0;
    for (double v : plane.profile_slab) top = std::max(top, v);
    for (size_t k = 0; k < plane.profile_far.size(); ++k)
      if (std::isfinite(plane.profile_far[k]))
        worst = std::max(worst, std::abs(plane.profile_far[k] - plane.profile_slab[k]));
    h << "<tr><td>" << Num(plane.distance_mm, 5) << "</td><td>" << Fmt(plane.centre_slab, 5)
      << "</td><td>" << Fmt(plane.centre_far, 5) << "</td><td>"
      << Fmt(100 * (plane.centre_far / plane.centre_slab - 1), 3) << " %</td><td>"
      << Fmt(top > 0 ? 100 * worst / top : NAN, 3) << " %"
      << (plane.note.empty() ? "" : " <b class=warn>(too near S: see its picture)</b>")
      << "</td></tr>\n";
  }
  h << "</table><div class=figs>\n";
  for (const ReportPlane& plane : r.planes) {
    SvgAxes a;
    a.width = 215;  // three to a row on A4 (184 mm, 695 px at 96 dpi)
    a.height = 190;
    a.left = 48;
    a.x0 = plane.profile_x_mm.front();
    a.x1 = plane.profile_x_mm.back();
    double top = 0;
    for (double v : plane.profile_slab) top = std::max(top, v);
    for (double v : plane.profile_far)
      if (std::isfinite(v)) top = std::max(top, v);
    a.y1 = top > 0 ? 1.05 * top : 1;
    h << "<figure>"
      << a.Open("x (mm) on y = 0, D = " + Num(plane.distance_mm, 5) + " mm",
                "E (" + r.IlluminanceUnit() + ")")
      << a.Polyline(plane.profile_x_mm, plane.profile_slab, "#1e46c8", 1.6)
      << a.Polyline(plane.profile_x_mm, plane.profile_far, "#c81e1e", 1.2, 4)
      << "</svg></figure>\n";
  }
  h << "</div><p class=note>Blue: the slab (exact model). Red dashed: the far field's inverse "
       "square from the luminaire's origin (left out where the direction was not seen).</p>"
       "</section>\n";
}

void CandelaTable(Page& p) {
  const ReportData& r = p.r;
  const IntensityDistribution& d = r.distribution;
  std::vector<int> planes;
  for (double c = 0; c < 360; c += std::max(30.0, d.c_deg[1] - d.c_deg[0]))
    if (d.StoredPlane(c) >= 0) planes.push_back(d.StoredPlane(c));
  const double g_step = std::max(5.0, d.gamma_deg[1] - d.gamma_deg[0]);
  auto& h = p.html;
  const size_t ng = d.gamma_deg.size();
  h << "<section class=page><h2>Candela table (" << r.IntensityUnit()
    << ")</h2><table class=candela><tr><th>&gamma; \\ C</th>";
  for (int ic : planes) h << "<th>" << Num(d.c_deg[ic], 4) << "&deg;</th>";
  h << "</tr>\n";
  size_t last_seen = 0;  // rows past the last gamma any plane saw are left out
  for (size_t k = 0; k < r.seen.size(); ++k)
    if (r.seen[k]) last_seen = std::max(last_seen, k % ng);
  for (size_t ig = 0; ig < ng; ++ig) {
    const double g = d.gamma_deg[ig];
    if (std::abs(g / g_step - std::round(g / g_step)) > 1e-6) continue;
    if (g > d.gamma_deg[last_seen] + g_step) break;
    h << "<tr><th>" << Num(g, 4) << "&deg;</th>";
    for (int ic : planes)
      h << "<td>" << (r.seen[size_t(ic) * ng + ig] ? Fmt(p.Scale(d.At(ic, ig)), 4) : "\u2014")
        << "</td>";
    h << "</tr>\n";
  }
  h << "</table><p class=note>&mdash;: not seen by the capture; no direction was seen beyond "
       "&gamma; = "
    << Deg(d.gamma_deg[last_seen]) << ".</p></section>\n";
}

void Uncertainty(Page& p) {
  const FarFieldUncertainty& u = p.r.uncertainty;
  auto& h = p.html;
  h << "<section><h2>Uncertainty</h2><table><tr><th class=l>term</th><th>relative standard "
       "uncertainty</th><th class=l>for</th><th class=l>basis</th></tr>\n";
  for (const UncertaintyTerm& t : u.terms)
    h << "<tr><td class=l>" << XmlEscape(t.name) << "</td><td>" << Num(100 * t.relative, 2)
      << " %</td><td class=l>"
      << (t.flux && t.peak ? "both"
          : t.flux         ? "flux"
                           : "peak")
      << "</td><td class=l>" << XmlEscape(t.basis) << "</td></tr>\n";
  h << "<tr><th class=l>expanded (k = " << Num(u.coverage_k, 2) << ")</th><th>flux "
    << Num(100 * u.FluxExpanded(), 2) << " %, peak " << Num(100 * u.PeakExpanded(), 2)
    << " %</th><td></td><td class=l>root sum of squares &times; k</td></tr></table>\n"
       "<ul class=note>";
  for (const std::string& n : u.notes) h << "<li>" << XmlEscape(n) << "</li>";
  h << "<li>IES keyword: [_UNCERTAINTY] " << XmlEscape(UncertaintyKeyword(u)) << "</li>";
  h << "</ul></section>\n";
}

void Colour(Page& p) {
  const ReportColour& c = p.r.colour;
  auto& h = p.html;
  h << "<section id=colour><h2>Colour</h2>";
  if (!c.present) {
    h << "<p><b>No colour calibration</b> (no calib/colour.json in the dataset): chromaticity "
         "and CCT need a camera RGB &rarr; CIE XYZ calibration from a photo of a colour chart "
         "(lumislab-calibrate colour).</p></section>\n";
    return;
  }
  h << "<table><tr><th class=l>chromaticity x, y (total light)</th><td>" << Fmt(c.x, 4) << ", "
    << Fmt(c.y, 4) << "</td></tr><tr><th class=l>CCT</th><td>"
    << (std::isfinite(c.cct_k) ? Fmt(c.cct_k, 4) + " K"
                               : "no CCT (Duv " + Fmt(c.duv, 3) +
                                     ": CCT is defined within |Duv| &le; 0.05 of the Planckian "
                                     "locus, CIE 15 / ANSI C78.377)")
    << "</td></tr>\n";
  for (const std::string& row : c.rows)
    h << "<tr><td class=l colspan=2>" << XmlEscape(row) << "</td></tr>\n";
  h << "</table>\n";
  if (!c.cells.empty()) {
    h << "<table><tr><th>&gamma; \\ C</th>";
    for (double cd : c.table_c) h << "<th>" << Num(cd, 4) << "&deg;</th>";
    h << "</tr>\n";
    for (size_t ig = 0; ig < c.table_gamma.size(); ++ig) {
      h << "<tr><th>" << Num(c.table_gamma[ig], 4) << "&deg;</th>";
      for (size_t ic = 0; ic < c.table_c.size(); ++ic) {
        const ReportColour::Cell& cell = c.cells[ig * c.table_c.size() + ic];
        if (std::isfinite(cell.cct_k))
          h << "<td>" << Fmt(cell.cct_k, 4) << " K<br><small>" << Fmt(cell.x, 4) << ", "
            << Fmt(cell.y, 4) << "</small></td>";
        else if (std::isfinite(cell.x) && std::isfinite(cell.y))
          h << "<td>no CCT<br><small>" << Fmt(cell.x, 4) << ", " << Fmt(cell.y, 4)
            << "</small></td>";
        else
          h << "<td>&mdash;</td>";
      }
      h << "</tr>\n";
    }
    h << "</table><p class=note>CCT and chromaticity x, y per direction (&mdash;: not seen or "
         "no chromaticity; no CCT: |Duv| &gt; 0.05).</p>\n";
  }
  h << "<p class=note>From " << XmlEscape(c.source) << ".</p></section>\n";
}

void Metadata(Page& p) {
  auto& h = p.html;
  h << "<section><h2>Capture and software</h2><table>\n";
  for (const auto& [k, v] : p.r.metadata)
    h << "<tr><th class=l>" << XmlEscape(k) << "</th><td class=l>" << XmlEscape(v)
      << "</td></tr>\n";
  h << "<tr><th class=l>report generated</th><td class=l>" << p.r.generated_utc << " by "
    << XmlEscape(p.r.software) << "</td></tr>\n";
  h << "<tr><th class=l>far field</th><td class=l>C 0&ndash;360&deg; by "
    << Num(p.r.distribution.c_deg[1] - p.r.distribution.c_deg[0], 4) << "&deg;, &gamma; 0&ndash;"
    << Num(p.r.gamma_span_deg, 4) << "&deg; by "
    << Num(p.r.distribution.gamma_deg[1] - p.r.distribution.gamma_deg[0], 4)
    << "&deg;; &gamma; = 0 along +z (towards the screen), C = 0 towards +x, C = 90 towards "
       "&minus;y (LM-63: counter-clockwise looking along &gamma; = 0)</td></tr>\n";
  h << "</table></section>\n";
}

}  // namespace

std::string ReportHtml(const ReportData& data) {
  Page p{data, {}};
  auto& h = p.html;
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>"
    << XmlEscape(data.title) << "</title><style>" << kCss << "</style></head><body>\n";
  h << "<h1>" << XmlEscape(data.title) << "</h1><p class=note>" << XmlEscape(data.measured)
    << " &middot; " << data.generated_utc << " &middot; " << XmlEscape(data.software) << "</p>\n";
  Summary(p);
  SpreadTable(p);
  Zonal(p);
  Polar(p);
  Linear(p);
  IsoCandela(p);
  Planes(p);
  NearField(p);
  Uncertainty(p);
  Colour(p);
  Metadata(p);
  CandelaTable(p);
  h << "</body></html>\n";
  return h.str();
}

}  // namespace lumislab
