// Tabulated spectral data for lib/photometry/colour.h, 380 - 780 nm every 5 nm (81 samples).
// Sources (all public; the numbers were copied from colour-science/colour 0.4.x,
// colour/colorimetry/datasets/cmfs.py, .../illuminants/sds.py and
// colour/characterisation/datasets/colour_checkers/sds.py, which cite the originals):
//  * CIE 1931 2-degree standard observer: CIE 15:2004 / CVRL (cvrl.org), the 1 nm table sampled
//    every 5 nm;
//  * CIE standard illuminants D50 and D65: CIE 15:2004 relative spectral power, 560 nm = 100;
//  * X-Rite (Macbeth) ColorChecker Classic 24: spectral reflectances measured by N. Ohta, "The
//    basis of color reproduction engineering" (1997), same as ISO 17321-1:2012's table.
#pragma once

namespace lumislab {

constexpr int kSpectralSamples = 81;
constexpr double kSpectralFirstNm = 380;
constexpr double kSpectralStepNm = 5;

extern const double kCmf1931[kSpectralSamples][3];
extern const double kD50[kSpectralSamples];
extern const double kD65[kSpectralSamples];
extern const double kColorCheckerOhta[24][kSpectralSamples];
extern const char* const kColorCheckerNames[24];

}  // namespace lumislab
