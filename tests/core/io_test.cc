// Round trips of the on-disk formats: EXR (pixels + attributes), slab, dataset.json,
// calib/screen.json, and the atomic-write guarantee.
#include <ImfChannelList.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "core/atomic_file.h"
#include "core/dataset.h"
#include "core/error.h"
#include "core/exr_io.h"
#include "core/screen_calibration.h"
#include "core/slab.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

class IoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("lumislab_io_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  // Files whose name does not start with '.', i.e. everything under a final name.
  int FinalFiles() const {
    int n = 0;
    for (auto& e : fs::directory_iterator(dir_)) n += !IsTemporaryName(e.path().string());
    return n;
  }
  int AllFiles() const {
    int n = 0;
    for (auto& e : fs::directory_iterator(dir_)) n += 1 + 0 * e.is_regular_file();
    return n;
  }
  fs::path dir_;
};

Dataset SmallDataset() {
  Dataset ds;
  ds.distance_mm = 750;
  ds.grid = {3, 2, 5};
  ds.screen_w_mm = 1200;
  ds.screen_h_mm = 800;
  const DualFilter f = DualFilter::Truncated(1);
  ds.filter = {"bell", 5, f.coefficients(), f.Peak2D()};
  ds.radiometric_scale = 2.5;
  ds.calibration = {"photos/calib_0.png", 14, 11, 60, {-420, -330}};
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 3; ++i)
      for (bool p : {true, false})
        ds.photos.push_back({i, j, p, "photos/" + PhotoFileName(i, j, p, "exr"), 1});
  return ds;
}

TEST_F(IoTest, ExrRoundTripsPixelsAndAttributes) {
  ImageF img(5, 3, 2);
  for (size_t k = 0; k < img.data.size(); ++k) img.data[k] = 0.25f * k - 1;
  ExrAttributes attr;
  attr.strings["units"] = "W/m^2";
  attr.doubles["d_mm"] = 750.5;
  attr.ints["i"] = 4;
  const std::string path = (dir_ / "a.exr").string();
  WriteExr(path, img, {"R", "mask"}, attr);
  ExrAttributes back;
  const ImageF in = ReadExr(path, {"R", "mask"}, &back);
  EXPECT_EQ(in.width, 5);
  EXPECT_EQ(in.height, 3);
  EXPECT_EQ(in.data, img.data);
  EXPECT_EQ(back.strings["units"], "W/m^2");
  EXPECT_DOUBLE_EQ(back.doubles["d_mm"], 750.5);
  EXPECT_EQ(back.ints["i"], 4);
  EXPECT_EQ(FinalFiles(), 1);
  EXPECT_EQ(AllFiles(), 1);  // no temporary left behind
  try {
    ReadExr(path, {"G"});
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_NE(std::string(e.what()).find("channel G"), std::string::npos);
  }
}

TEST_F(IoTest, CorruptExrIsBadInputNamingTheFile) {
  const std::string path = (dir_ / "bad.exr").string();
  std::ofstream(path) << "not an exr at all";
  try {
    ReadExr(path, {"R"});
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos);
  }
}

TEST_F(IoTest, FailedWriteLeavesNothingUnderTheFinalName) {
  const std::string path = (dir_ / "out.txt").string();
  EXPECT_THROW(WriteAtomically(path,
                               [](const std::string& tmp) {
                                 std::ofstream(tmp) << "half";
                                 throw IoError(tmp, "disk full (simulated)");
                               }),
               Error);
  EXPECT_FALSE(fs::exists(path));
  EXPECT_EQ(AllFiles(), 0);
  WriteTextAtomically(path, "whole");
  EXPECT_EQ(ReadTextFile(path), "whole");
}

TEST_F(IoTest, SlabRoundTripAndPartialSlabs) {
  const Dataset ds = SmallDataset();
  SlabInfo info = SlabInfo::FromDataset(ds, 8);
  EXPECT_EQ(info.layout.res_x, 8);
  SlabPosition p;
  p.i = 2;
  p.j = 1;
  p.irradiance = ImageF(8, 8, 3);
  p.mask = ImageF(8, 8, 1, 1.f);
  for (size_t k = 0; k < p.irradiance.data.size(); ++k) p.irradiance.data[k] = 1e-6f * k - 3e-5f;
  p.mask.data[5] = 0;
  WriteSlabPosition(dir_.string(), info, p);
  info.MarkPresent(2, 1);
  info.MarkPresent(0, 0);
  info.MarkPresent(2, 1);
  info.Save(dir_.string());

  const SlabInfo back = SlabInfo::Load(dir_.string());
  EXPECT_EQ(back.present.size(), 2u);
  EXPECT_TRUE(back.IsPresent(2, 1));
  EXPECT_FALSE(back.IsPresent(1, 1));
  EXPECT_FALSE(back.Complete());
  EXPECT_EQ(back.units, "W/m^2");
  EXPECT_EQ(back.filter.dual_coefficients, ds.filter.dual_coefficients);
  const SlabPosition q = ReadSlabPosition(dir_.string(), back, 2, 1);
  EXPECT_EQ(q.irradiance.data, p.irradiance.data);
  EXPECT_EQ(q.mask.data, p.mask.data);
  ExrAttributes attr;
  ReadExr(SlabPositionPath(dir_.string(), 2, 1), {"R"}, &attr);
  EXPECT_DOUBLE_EQ(attr.doubles["lumislab.centre_x_mm"], 5.0);
  EXPECT_DOUBLE_EQ(attr.doubles["lumislab.distance_mm"], 750.0);
  EXPECT_EQ(attr.ints["lumislab.j"], 1);
  const auto scanned = ScanSlabPositions(dir_.string(), back);
  ASSERT_EQ(scanned.size(), 1u);  // (0,0) is listed but its file is not there yet
  EXPECT_EQ(scanned[0], std::make_pair(2, 1));
  // Reading under the wrong position or resolution is refused.
  EXPECT_THROW(ReadSlabPosition(dir_.string(), SlabInfo::FromDataset(ds, 9), 2, 1), Error);
  // A resumed run at another resolution does not count the file as done...
  EXPECT_TRUE(ScanSlabPositions(dir_.string(), SlabInfo::FromDataset(ds, 9)).empty());
  // ...nor a truncated one (a run killed without atomic writes, a full disk).
  const std::string path = SlabPositionPath(dir_.string(), 2, 1);
  fs::resize_file(path, fs::file_size(path) - 40);
  EXPECT_TRUE(ScanSlabPositions(dir_.string(), back).empty());
}

TEST_F(IoTest, ExrHeaderClaimingAHugeImageIsRefusedBeforeAllocating) {
  // A few hundred bytes whose header says 32768 x 32768 (12 GB as float RGB).
  const std::string path = (dir_ / "huge.exr").string();
  {
    Imf::Header header(32768, 32768);
    header.channels().insert("R", Imf::Channel(Imf::HALF));
    Imf::OutputFile file(path.c_str(), header);  // no pixels written: a header-only file
  }
  ASSERT_LT(fs::file_size(path), 1 << 20);
  try {
    ReadExr(path, {"R"});
    ADD_FAILURE() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_NE(std::string(e.what()).find("huge.exr: not a readable EXR file: header: dataWindow "
                                         "of 32768 x 32768 pixels"),
              std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(ExrComplete(path, 32768, 32768));
}

std::string FileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// A hostile EXR header: ReadExr and ExrChannelNames refuse the file as bad input (exit 2) with a
// message holding `what`, ExrComplete says no, and all of it within 5 s (no gigabytes
// allocated and cleared first).
void ExpectExrRefusedAtOnce(const std::string& path, const std::string& what, int width,
                            int height) {
  const auto start = std::chrono::steady_clock::now();
  for (const auto& read : std::vector<std::function<void()>>{[&] { ReadExr(path, {"Y"}); },
                                                             [&] { ExrChannelNames(path); }}) {
    try {
      read();
      ADD_FAILURE() << path << ": accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.exit_code(), 2);
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  }
  EXPECT_FALSE(ExrComplete(path, width, height));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5);
}

// OpenEXR allocates a header attribute at the size the file states: a small file claiming a
// 2 GB attribute is refused before OpenEXR reads it (found by fuzz_slab_position).
TEST_F(IoTest, ExrAttributeLargerThanTheFileIsRefusedBeforeAllocating) {
  const std::string path = (dir_ / "attribute.exr").string();
  ExrAttributes attributes;
  attributes.strings["probe"] = "x";
  WriteExr(path, ImageF(4, 3, 1), {"Y"}, attributes);
  std::string bytes = FileBytes(path);
  const size_t at = bytes.find(std::string("probe\0string\0", 13));
  ASSERT_NE(at, std::string::npos);
  for (int k = 0; k < 4; ++k) bytes[at + 13 + size_t(k)] = k == 3 ? '\x7f' : '\xf0';  // ~2.1 GB
  std::ofstream(path, std::ios::binary) << bytes;
  ExpectExrRefusedAtOnce(
      path, "attribute.exr: not a readable EXR file: header: attribute probe: size", 4, 3);
}

// Found by fuzz_slab_position in CI: a data window tens of millions of pixels wide made OpenEXR's
// InputFile allocate and clear a line buffer of gigabytes before ReadExr could check the size
// (OpenEXR itself refuses only windows near 2^31). The header walk bounds the window, and the
// decode buffer it implies, first.
TEST_F(IoTest, ExrDataWindowTensOfMillionsWideIsRefusedBeforeOpenExrAllocates) {
  const std::string path = (dir_ / "window.exr").string();
  WriteExr(path, ImageF(4, 3, 1), {"Y"});
  std::string bytes = FileBytes(path);
  const std::string key("dataWindow\0box2i\0\x10\0\0\0", 21);
  const size_t at = bytes.find(key);
  ASSERT_NE(at, std::string::npos);
  const int32_t window[4] = {-(1 << 25), 0, (1 << 25) - 1, 0};  // 2^26 wide, 1 high
  std::memcpy(&bytes[at + key.size()], window, sizeof window);  // little-endian, as EXR is
  std::ofstream(path, std::ios::binary) << bytes;
  ExpectExrRefusedAtOnce(
      path, "window.exr: not a readable EXR file: header: dataWindow of 67108864 x 1 pixels", 4, 3);
}

// Found by fuzz_slab_position in CI: a channel list running past its stated size makes OpenEXR
// read the rest of the header from another place than the size says, where a string attribute
// claims 1.7 GB. The header walk reads a channel list as OpenEXR does and refuses it.
TEST_F(IoTest, ExrChannelListRunningPastItsSizeIsRefused) {
  ExpectExrRefusedAtOnce(
      std::string(LUMISLAB_SOURCE_DIR) + "/tests/data/hostile/exr_chlist_overrun.exr",
      "exr_chlist_overrun.exr: not a readable EXR file: header: attribute channels: a channel ", 8,
      6);
}

// Found by fuzz_slab_position: a preview attribute whose width times height overflowed 64 bits
// in the header walk's own size check (undefined behaviour, caught by UBSan).
TEST_F(IoTest, ExrPreviewOfOverflowingSizeIsRefused) {
  ExpectExrRefusedAtOnce(
      std::string(LUMISLAB_SOURCE_DIR) + "/tests/data/hostile/exr_preview_size_overflow.exr",
      "exr_preview_size_overflow.exr: not a readable EXR file: header: attribute channels: a "
      "preview image",
      8, 6);
}

TEST_F(IoTest, TemporaryNamesFitAndOrphansOfDeadProcessesAreRemoved) {
  // A legal 254-byte name still gets a temporary name within the 255-byte limit.
  const std::string name = std::string(250, 'a') + ".exr";
  const std::string tmp = TemporaryPathFor((dir_ / name).string());
  EXPECT_LE(fs::path(tmp).filename().string().size(), 255u);
  EXPECT_TRUE(IsTemporaryName(tmp));
  WriteTextAtomically((dir_ / name).string(), "x");
  EXPECT_TRUE(fs::exists(dir_ / name));
  // An orphan of a process that is gone is removed; one of a live process (this one) is kept.
  std::ofstream(dir_ / ".pos_1_2.tmp999999999_3.exr") << "half";
  const std::string mine = TemporaryPathFor((dir_ / "slab.json").string());
  std::ofstream(mine) << "{";
  std::ofstream(dir_ / ".hidden_but_not_ours") << "keep";
  EXPECT_EQ(RemoveOrphanedTemporaries(dir_.string()), 1);
  EXPECT_FALSE(fs::exists(dir_ / ".pos_1_2.tmp999999999_3.exr"));
  EXPECT_TRUE(fs::exists(mine));
  EXPECT_TRUE(fs::exists(dir_ / ".hidden_but_not_ours"));
}

// The exit code and message of what `f` throws; {0, ""} when it throws nothing.
std::pair<int, std::string> Thrown(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return {e.exit_code(), e.what()};
  }
  return {0, ""};
}

// docs/architecture.md §7.5: an output replaces only a regular file. A link is refused (neither
// replaced nor written through), a FIFO or device is refused, and nothing changes.
TEST_F(IoTest, OutputsRefuseLinksAndSpecialFiles) {
  const std::string target = (dir_ / "target.ies").string();
  WriteTextAtomically(target, "the target");
  const std::string link = (dir_ / "link.ies").string();
  ASSERT_EQ(symlink(target.c_str(), link.c_str()), 0);
  for (const auto& attempt : std::vector<std::function<void()>>{
           [&] { CheckOutputPath(link); }, [&] { WriteTextAtomically(link, "new"); }}) {
    const auto [code, message] = Thrown(attempt);
    EXPECT_EQ(code, 2);
    EXPECT_NE(message.find(link + ": is a symbolic link"), std::string::npos) << message;
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(link)));
    EXPECT_EQ(ReadTextFile(target), "the target");
  }
  const std::string fifo = (dir_ / "fifo.ies").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0);
  for (const auto& attempt : std::vector<std::function<void()>>{
           [&] { CheckOutputPath(fifo); }, [&] { WriteTextAtomically(fifo, "new"); }}) {
    const auto [code, message] = Thrown(attempt);
    EXPECT_EQ(code, 2);
    EXPECT_NE(message.find(fifo + ": not a regular file (a FIFO)"), std::string::npos) << message;
    EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));
  }
  // A character device: only checked (writing beside it would write into /dev), and left as is.
  struct stat before {
  }, after{};
  ASSERT_EQ(stat("/dev/null", &before), 0);
  ASSERT_TRUE(S_ISCHR(before.st_mode));
  const auto [code, message] = Thrown([] { CheckOutputPath("/dev/null"); });
  EXPECT_EQ(code, 2);
  EXPECT_NE(message.find("/dev/null: not a regular file (a character device)"), std::string::npos)
      << message;
  ASSERT_EQ(stat("/dev/null", &after), 0);
  EXPECT_TRUE(S_ISCHR(after.st_mode));
  EXPECT_EQ(before.st_rdev, after.st_rdev);
  EXPECT_EQ(before.st_ino, after.st_ino);
  // A folder cannot be replaced by a file (exit 3); a missing path or a regular file passes.
  fs::create_directories(dir_ / "folder.ies");
  EXPECT_EQ(Thrown([&] { CheckOutputPath((dir_ / "folder.ies").string()); }).first, 3);
  EXPECT_EQ(Thrown([&] { CheckOutputPath((dir_ / "new.ies").string()); }).first, 0);
  EXPECT_EQ(Thrown([&] { CheckOutputPath(target); }).first, 0);
  // The last line: a link that appears while the output is being written is refused at the
  // rename, and the temporary file is removed.
  const std::string late = (dir_ / "late.ies").string();
  const auto [late_code, late_message] = Thrown([&] {
    WriteAtomically(late, [&](const std::string& tmp) {
      std::ofstream(tmp) << "x";
      ASSERT_EQ(symlink(target.c_str(), late.c_str()), 0);
    });
  });
  EXPECT_EQ(late_code, 2) << late_message;
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(late)));
  EXPECT_EQ(ReadTextFile(target), "the target");
  for (auto& e : fs::directory_iterator(dir_))
    EXPECT_FALSE(IsTemporaryName(e.path().string())) << e.path();
}

TEST_F(IoTest, SlabRefusesNonFiniteValues) {
  const SlabInfo info = SlabInfo::FromDataset(SmallDataset(), 4);
  SlabPosition p{0, 0, ImageF(4, 4, 3), ImageF(4, 4, 1, 1.f)};
  p.irradiance.data[7] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(WriteSlabPosition(dir_.string(), info, p), Error);
  EXPECT_EQ(FinalFiles(), 0);
}

TEST_F(IoTest, DatasetRoundTripAndValidation) {
  const Dataset ds = SmallDataset();
  ds.Save(dir_.string());
  const Dataset back = Dataset::Load(dir_.string());
  EXPECT_EQ(back.grid.nu, 3);
  EXPECT_EQ(back.photos.size(), 12u);
  EXPECT_EQ(back.PhotosOf(1, 1).size(), 2u);
  EXPECT_DOUBLE_EQ(*back.radiometric_scale, 2.5);
  EXPECT_EQ(back.calibration.squares_x, 14);
  EXPECT_DOUBLE_EQ(back.calibration.origin_mm.y(), -330);
  EXPECT_EQ(back.filter.dual_coefficients, ds.filter.dual_coefficients);

  auto expect_error = [&](const std::string& from, const std::string& to, const std::string& msg) {
    std::string text = ReadTextFile((dir_ / "dataset.json").string());
    const size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    const fs::path bad = dir_ / "bad";
    fs::create_directories(bad);
    std::ofstream(bad / "dataset.json") << text;
    try {
      Dataset::Load(bad.string());
      ADD_FAILURE() << "accepted " << to;
    } catch (const Error& e) {
      EXPECT_EQ(e.exit_code(), 2);
      EXPECT_NE(std::string(e.what()).find(msg), std::string::npos) << e.what();
    }
  };
  expect_error("\"nu\": 3", "\"nu\": -3",
               "dataset.json: setup.grid.nu: expected integer in [1, 1000], got -3");
  expect_error("\"peak\": ", "\"peak\": -", "filter.peak: expected number > 0");
  expect_error("\"slide\": \"n\"", "\"slide\": \"q\"", "photos[1].slide: expected one of p|n");
  expect_error("\"file\": \"photos/pos_2_1_n.exr\"", "\"file\": \"/etc/passwd\"",
               "photos[11].file");
  expect_error("\"photo\": \"photos/calib_0.png\"", "\"photo\": \"../calib_0.png\"",
               "calibration.photo: expected a path relative to the photo folder");
  // The slides are Phi~ / peak: a peak that does not belong to the coefficients is refused.
  expect_error("\"peak\": ", "\"peak\": 1.5e0, \"was_peak\": ", "filter.peak: expected max |Phi~|");
  // A square board is refused when the dataset is read, not only by calibrate.
  expect_error("\"squares\": [", "\"squares\": [13, 13], \"was\": [",
               "calibration.target.squares: expected squares_x != squares_y");
  // A newer schema is refused, not misread.
  expect_error("\"schema_version\": 2", "\"schema_version\": 4", "schema_version");
  expect_error("\"schema_version\": 2", "\"schema_version\": 3, \"photo_folder\": \"\"",
               "photo_folder: expected a folder path");
}

// A partial dataset (import --partial, watch) lists the positions it lacks: exactly those
// without photos; a position missing without being listed, or listed with photos, is refused.
TEST_F(IoTest, PartialDatasetListsItsMissingPositions) {
  Dataset ds = SmallDataset();
  ds.photos.erase(std::remove_if(ds.photos.begin(), ds.photos.end(),
                                 [](const PhotoEntry& e) { return e.i == 2 && e.j == 1; }),
                  ds.photos.end());
  ds.missing_positions = {{2, 1}};
  ds.Save(dir_.string());
  const Dataset back = Dataset::Load(dir_.string());
  EXPECT_TRUE(back.Partial());
  EXPECT_EQ(back.missing_positions, (std::vector<std::pair<int, int>>{{2, 1}}));
  EXPECT_TRUE(back.PhotosOf(2, 1).empty());
  EXPECT_EQ(back.photos.size(), 10u);
  auto refused = [&](const std::string& missing, const std::string& msg) {
    nlohmann::json j = ds.ToJson();
    j["missing_positions"] = nlohmann::json::parse(missing);
    try {
      Dataset::Parse(JsonDocument::Parse(j.dump(), "dataset.json"), dir_.string());
      ADD_FAILURE() << "accepted " << missing;
    } catch (const Error& e) {
      EXPECT_EQ(e.exit_code(), 2);
      EXPECT_NE(std::string(e.what()).find(msg), std::string::npos) << e.what();
    }
  };
  refused("[]", "none for position (2, 1)");
  refused("[[2, 1], [0, 0]]", "missing_positions[1]: expected a position without photos");
  refused("[[2, 1], [2, 1]]", "missing_positions[1]: expected a position not listed before");
  refused("[[3, 1]]", "missing_positions[0][0]");
}

// Old files stay readable: a version-1 dataset.json reads with the version-2 defaults.
TEST_F(IoTest, ReadsADatasetOfSchemaVersion1) {
  const Dataset ds = Dataset::Load(std::string(LUMISLAB_SOURCE_DIR) + "/tests/data/v1");
  EXPECT_EQ(ds.grid.nu, 2);
  EXPECT_EQ(ds.photos.size(), 4u);
  EXPECT_EQ(ds.photo_transfer, "auto");
  EXPECT_EQ(ds.black_level, 0.0);
  EXPECT_EQ(ds.white_level, 1.0);
  EXPECT_DOUBLE_EQ(*ds.radiometric_scale, 1.92376);
}

TEST_F(IoTest, ScreenCalibrationRoundTripAndDistortionInverse) {
  ScreenCalibration c;
  c.image_width = 1600;
  c.image_height = 1200;
  c.screen_from_image << 0.9, 0.05, -700, -0.02, -0.95, 560, 1e-5, 2e-5, 1;
  c.k1 = -0.08;
  c.k2 = 0.01;
  c.centre_px = {799.5, 599.5};
  c.scale_px = 1000;
  c.rms_px = 0.03;
  c.corners_used = 143;
  const std::string path = (dir_ / "screen.json").string();
  c.Save(path);
  const ScreenCalibration b = ScreenCalibration::Load(path);
  EXPECT_TRUE(b.screen_from_image.isApprox(c.screen_from_image));
  EXPECT_DOUBLE_EQ(b.k1, -0.08);
  EXPECT_EQ(b.corners_used, 143);
  for (double x : {0.0, 400.0, 1599.0})
    for (double y : {0.0, 700.0, 1199.0}) {
      const Eigen::Vector2d px(x, y);
      EXPECT_LT((b.Distort(b.Undistort(px)) - px).norm(), 1e-9);
      EXPECT_LT((b.ImageFromScreen(b.ScreenFromImage(px)) - px).norm(), 1e-7);
    }
}

}  // namespace
}  // namespace lumislab
