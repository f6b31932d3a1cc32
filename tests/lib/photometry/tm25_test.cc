// TM-25 ray files: the byte layout, round trip, files from other writers' flag sets, bad input.
#include "lib/photometry/tm25.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "core/error.h"

namespace lumislab {
namespace {

std::string TempPath(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / "lumislab_tm25_test";
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

Tm25RaySet RandomRays(int n, bool photometric) {
  Tm25RaySet set;
  set.photometric = photometric;
  set.date_time = "2026-12-02T03:00:00Z";
  set.name = "test source";
  set.manufacturer = "lumislab";
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1, 1);
  for (int k = 0; k < n; ++k) {
    float kx = u(rng), ky = u(rng), kz = std::abs(u(rng)) + 0.1f;
    const float norm = std::sqrt(kx * kx + ky * ky + kz * kz);
    set.rays.push_back(
        {10 * u(rng), 10 * u(rng), 0, kx / norm, ky / norm, kz / norm, 0.5f + 0.5f * u(rng)});
  }
  set.luminous_flux_lm = photometric ? set.FluxSum() : std::nan("");
  set.radiant_flux_w = photometric ? std::nan("") : set.FluxSum();
  return set;
}

std::string Bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
void Write(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}
template <typename T>
T At(const std::string& bytes, size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof v);
  return v;
}
template <typename T>
void Set(std::string* bytes, size_t offset, T v) {
  std::memcpy(bytes->data() + offset, &v, sizeof v);
}

TEST(Tm25, WritesTheStandardLayoutAndReadsItBack) {
  for (bool photometric : {true, false}) {
    const Tm25RaySet set = RandomRays(100, photometric);
    const std::string path = TempPath(photometric ? "lm.ray" : "w.ray");
    WriteTm25(set, path);
    const std::string bytes = Bytes(path);
    ASSERT_EQ(bytes.size(), kTm25FixedHeaderBytes + 100 * 7 * 4);
    EXPECT_EQ(bytes.substr(0, 4), "TM25");
    EXPECT_EQ(At<int32_t>(bytes, 4), 2013);
    EXPECT_EQ(At<uint64_t>(bytes, 20), 100u);
    EXPECT_EQ(At<int32_t>(bytes, 256), 1);                    // position flag
    EXPECT_EQ(At<int32_t>(bytes, 264), photometric ? 0 : 1);  // radiant flux flag
    EXPECT_EQ(At<int32_t>(bytes, 272), photometric ? 1 : 0);  // luminous flux flag
    EXPECT_EQ(At<char32_t>(bytes, 288), U't');                // name, UTF-32
    EXPECT_FLOAT_EQ(At<float>(bytes, kTm25FixedHeaderBytes + 6 * 4), set.rays[0].flux);
    const Tm25RaySet back = ReadTm25(path);
    EXPECT_EQ(back.photometric, photometric);
    EXPECT_EQ(back.name, "test source");
    EXPECT_EQ(back.date_time, set.date_time);
    ASSERT_EQ(back.rays.size(), set.rays.size());
    for (size_t k = 0; k < set.rays.size(); ++k) {
      EXPECT_EQ(back.rays[k].x, set.rays[k].x);
      EXPECT_NEAR(back.rays[k].kz, set.rays[k].kz, 1e-6);
      EXPECT_EQ(back.rays[k].flux, set.rays[k].flux);
    }
    EXPECT_NEAR(back.FluxSum(), set.FluxSum(), 1e-9);
    EXPECT_FLOAT_EQ(photometric ? back.luminous_flux_lm : back.radiant_flux_w, set.FluxSum());
    EXPECT_TRUE(std::isnan(photometric ? back.radiant_flux_w : back.luminous_flux_lm));
  }
}

// A file with both flux columns and a wavelength column (as spectral ray files have): the
// luminous flux column is the one kept.
TEST(Tm25, ReadsFilesWithMoreColumns) {
  const std::string path = TempPath("three.ray");
  WriteTm25(RandomRays(3, true), path);
  std::string bytes = Bytes(path);
  Set<int32_t>(&bytes, 264, 1);  // radiant flux flag
  Set<int32_t>(&bytes, 268, 1);  // wavelength flag
  std::string rays;
  for (int k = 0; k < 3; ++k) {
    const char* ray = bytes.data() + kTm25FixedHeaderBytes + k * 28;
    const float extra[3] = {9.f, 555.f, float(k + 1)};  // radiant, wavelength, luminous
    rays.append(ray, 24).append(reinterpret_cast<const char*>(extra), 12);
  }
  bytes = bytes.substr(0, kTm25FixedHeaderBytes) + rays;
  Write(path, bytes);
  const Tm25RaySet back = ReadTm25(path);
  ASSERT_EQ(back.rays.size(), 3u);
  EXPECT_TRUE(back.photometric);
  EXPECT_EQ(back.rays[2].flux, 3.f);
}

TEST(Tm25, BadInputNamesTheFileAndTheField) {
  const std::string path = TempPath("good.ray");
  WriteTm25(RandomRays(10, true), path);
  const std::string good = Bytes(path);
  struct Case {
    const char* what;
    std::string bytes;
    const char* expected;
  };
  std::string nan_ray = good, zero_dir = good, bad_flag = good, bad_magic = good;
  std::string negative = good;
  Set<float>(&nan_ray, kTm25FixedHeaderBytes + 3 * 28 + 4, std::nanf(""));
  for (int k = 3; k < 6; ++k) Set<float>(&zero_dir, kTm25FixedHeaderBytes + 28 + 4 * k, 0.f);
  Set<int32_t>(&bad_flag, 276, 2);
  Set<float>(&negative, kTm25FixedHeaderBytes + 24, -1.f);
  bad_magic[0] = 'X';
  const Case cases[] = {
      {"truncated rays", good.substr(0, good.size() - 10),
       "number of rays (4.7.1.6): the header says 10 rays of 7 values"},
      {"truncated header", good.substr(0, 1000), "description field 4.7.3.1: the file ends"},
      {"NaN", nan_ray, "ray 3, value 2: expected a finite number"},
      {"zero direction", zero_dir, "ray 1: direction (kx, ky, kz): expected a unit vector"},
      {"flag 2", bad_flag, "Stokes flag (4.7.2.6): expected 0 or 1, got 2"},
      {"negative flux", negative, "ray 0: flux: expected a number >= 0"},
      {"not TM-25", bad_magic, "file type (4.7.1.1): expected \"TM25\""},
  };
  for (const Case& c : cases) {
    const std::string bad = TempPath("bad.ray");
    Write(bad, c.bytes);
    try {
      ReadTm25(bad);
      ADD_FAILURE() << c.what << ": read";
    } catch (const Error& e) {
      EXPECT_EQ(e.exit_code(), 2) << c.what;
      EXPECT_NE(std::string(e.what()).find(bad + ": "), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos)
          << c.what << ": " << e.what();
    }
  }
}

// Found by fuzz/fuzz_tm25 (fuzz/corpus/fuzz_tm25/regression_text_block_2gib.ray): a header that
// says its text block (4.7.1.15) holds 2^31 - 32 bytes made the reader allocate a 2 GiB buffer
// before finding the file short. Now every size from the header is checked against the file
// first: exit 2 naming the field, and no allocation (this test runs under ASan's allocation
// limit in the sanitized build too). The same for 1024 additional column names.
TEST(Tm25, HeaderSizesAreCheckedAgainstTheFileBeforeUse) {
  const std::string path = TempPath("sizes.ray");
  WriteTm25(RandomRays(3, true), path);
  const std::string good = Bytes(path);
  std::string text = good, columns = good;
  Set<int32_t>(&text, 84, 0x7fffffe0);
  Set<int32_t>(&columns, 80, 1024);
  for (const auto& [bytes, expected] : std::vector<std::pair<std::string, std::string>>{
           // The size needed is in the message: it was checked before anything was read.
           {text,
            "additional text block (4.7.6): the file ends before it (truncated: 36372 "
            "bytes, 2147483616 needed from byte 36288)"},
           {columns,
            "additional column name 1 (4.7.5): the file ends before it (truncated: "
            "36372 bytes, 512 needed from byte 36288)"}}) {
    Write(path, bytes);
    try {
      ReadTm25(path);
      ADD_FAILURE() << expected << ": read";
    } catch (const Error& e) {
      EXPECT_EQ(e.exit_code(), 2) << e.what();
      EXPECT_NE(std::string(e.what()).find(path + ": " + expected), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace lumislab
