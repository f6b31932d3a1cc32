// lumislab-acquire import (docs/formats.md §3): a synthetic capture is turned into what a camera
// leaves behind (a folder of IMG_0001.PNG ... in capture order, the board photo, no
// dataset.json) plus a setup file; import, calibrate and reconstruct must then give exactly the
// slab of the original dataset, the camera's folder must stay untouched, and every way of
// naming the photos (name order, manifest, pattern) must give the same dataset. Bad folders and
// descriptions exit 2 naming the file, line or position, and write nothing.
#include "acquire/import.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "core/dataset.h"
#include "core/slab_compare.h"
#include "lib/photo/camera_write.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

using testing::ReadBinaryFile;
using testing::RunToolIn;
using testing::SnapshotTree;

class Import : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = testing::FreshDir(std::string("import_") +
                              ::testing::UnitTest::GetInstance()->current_test_info()->name());
    testing::WriteFile(root_ + "/scene.json",
                       testing::SceneJson(3, 2,
                                          R"({"size_px": [320, 240], "focal_px": 280,
                               "position_mm": [0, -200, 2400], "look_at_mm": [0, 0, 750]})",
                                          R"([{"type": "quantization", "bit_depth": 16}])"));
    Ok("lumislab-acquire", "synth --scene scene.json --out original --truth-resolution 40");
    // The camera's folder: the slide photos renamed in capture order (rows, p then n).
    const Dataset ds = Dataset::Load(root_ + "/original");
    fs::create_directories(root_ + "/camera");
    int k = 1;
    for (int j = 0; j < ds.grid.nv; ++j)
      for (int i = 0; i < ds.grid.nu; ++i)
        for (const bool positive : {true, false})
          for (const auto& e : ds.PhotosOf(i, j))
            if (e.positive == positive) {
              names_.push_back(Copy(ds.PhotoPath(e.file), k++));
              manifest_ += std::to_string(i) + "," + std::to_string(j) + "," +
                           (positive ? "p" : "n") + "," + names_.back() + ",1\n";
            }
    fs::copy_file(ds.PhotoPath(ds.calibration.photo), root_ + "/camera/BOARD.PNG");
    nlohmann::json setup = nlohmann::json::parse(ReadBinaryFile(root_ + "/original/dataset.json"));
    setup.erase("photos");
    setup.erase("synthetic");
    setup["calibration"]["photo"] = "BOARD.PNG";
    testing::WriteFile(root_ + "/setup.json", setup.dump(2));
    testing::WriteFile(root_ + "/captures.csv", "i,j,slide,file,exposure\n" + manifest_);
  }
  std::string Copy(const std::string& from, int k) {
    char name[32];
    std::snprintf(name, sizeof name, "IMG_%04d.PNG", k);
    fs::copy_file(from, root_ + "/camera/" + name);
    return name;
  }
  void Ok(const std::string& tool, const std::string& args) {
    const auto r = RunToolIn(root_, tool, args, 120);
    ASSERT_EQ(r.exit_code, 0) << tool << " " << args << "\n" << r.output;
  }
  // Import refused: exit 2, the message names `names`, and nothing was written.
  void Refused(const std::string& args, const std::vector<std::string>& names) {
    const auto before = SnapshotTree(root_);
    const std::string setup =
        args.find("--setup") == std::string::npos ? " --setup setup.json" : "";
    const auto r =
        RunToolIn(root_, "lumislab-acquire", "import --photos camera --out ds " + args + setup, 60);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.output;
    for (const auto& n : names)
      EXPECT_NE(r.output.find(n), std::string::npos) << n << "\n" << r.output;
    EXPECT_EQ(testing::DiffSnapshots(before, SnapshotTree(root_)), std::vector<std::string>{})
        << args;
  }
  std::string root_, manifest_;
  std::vector<std::string> names_;
};

TEST_F(Import, CameraFolderGivesTheOriginalSlab) {
  const auto camera_before = SnapshotTree(root_ + "/camera");
  Ok("lumislab-acquire",
     "import --photos camera --setup setup.json --out ds --order name "
     "--exposure 1");
  // Nothing copied: the dataset folder holds dataset.json alone; it names the camera's folder.
  EXPECT_EQ(testing::CountFinalFiles(root_ + "/ds"), 1);
  const Dataset ds = Dataset::Load(root_ + "/ds");
  EXPECT_EQ(ds.photo_folder, "../camera");
  EXPECT_EQ(ds.photos.size(), 12u);
  Ok("lumislab-calibrate", "screen --dataset ds");
  Ok("lumislab-reconstruct", "--dataset ds --resolution 40");
  Ok("lumislab-calibrate", "screen --dataset original");
  Ok("lumislab-reconstruct", "--dataset original --resolution 40");
  const SlabComparison c = CompareSlabs(root_ + "/ds/slab", root_ + "/original/slab", 0.0);
  EXPECT_EQ(c.positions.size(), 6u);
  EXPECT_LE(c.max_relative_l2, 1e-7);
  EXPECT_EQ(testing::DiffSnapshots(camera_before, SnapshotTree(root_ + "/camera")),
            std::vector<std::string>{});
  // A second run skips; --force writes the same file again.
  const std::string json = ReadBinaryFile(root_ + "/ds/dataset.json");
  Ok("lumislab-acquire",
     "import --photos camera --setup setup.json --out ds --order name "
     "--exposure 1 --force");
  EXPECT_EQ(ReadBinaryFile(root_ + "/ds/dataset.json"), json);
}

TEST_F(Import, ManifestPatternAndOrderAgree) {
  Ok("lumislab-acquire",
     "import --photos camera --setup setup.json --out by_order --order name "
     "--exposures 1");
  Ok("lumislab-acquire",
     "import --photos camera --setup setup.json --out by_manifest --manifest captures.csv");
  // The pattern needs names that carry the position: a second folder named so.
  fs::create_directories(root_ + "/named");
  const Dataset by_order = Dataset::Load(root_ + "/by_order");
  for (const auto& e : by_order.photos)
    fs::copy_file(by_order.PhotoPath(e.file), root_ + "/named/pos" + std::to_string(e.i) + "-" +
                                                  std::to_string(e.j) + "_" +
                                                  (e.positive ? "P" : "N") + "_x1.png");
  fs::copy_file(root_ + "/camera/BOARD.PNG", root_ + "/named/BOARD.PNG");
  Ok("lumislab-acquire",
     "import --photos named --setup setup.json --out by_pattern "
     "--pattern pos{i}-{j}_{slide}_x{exposure}.png");
  const Dataset by_manifest = Dataset::Load(root_ + "/by_manifest");
  const Dataset by_pattern = Dataset::Load(root_ + "/by_pattern");
  ASSERT_EQ(by_manifest.photos.size(), by_order.photos.size());
  ASSERT_EQ(by_pattern.photos.size(), by_order.photos.size());
  for (size_t k = 0; k < by_order.photos.size(); ++k) {
    const PhotoEntry &a = by_order.photos[k], &b = by_manifest.photos[k], &c = by_pattern.photos[k];
    EXPECT_EQ(a.file, b.file);
    EXPECT_EQ(ReadBinaryFile(by_order.PhotoPath(a.file)),
              ReadBinaryFile(by_pattern.PhotoPath(c.file)));
    for (const PhotoEntry* e : {&b, &c}) {
      EXPECT_EQ(std::make_tuple(a.i, a.j, a.positive, a.exposure),
                std::make_tuple(e->i, e->j, e->positive, e->exposure))
          << a.file;
    }
  }
}

// A camera's JPEGs with EXIF: --order capture follows the EXIF time (the names are shuffled so
// that name order is wrong), the exposure is t ISO / N^2 from EXIF, a photo of another camera
// model is refused naming it, and --order capture without a time is refused.
TEST_F(Import, ExifGivesOrderExposureAndCamera) {
  const Dataset ds = Dataset::Load(root_ + "/original");
  fs::create_directories(root_ + "/jpeg");
  PhotoExif exif;
  exif.exposure_time = 1.0 / 30;
  exif.f_number = 8;
  exif.iso = 200;
  exif.make = "Lumislab";
  exif.model = "Synthetic 1";
  std::vector<std::string> jpegs;
  for (size_t k = 0; k < names_.size(); ++k) {
    const cv::Mat png = cv::imread(root_ + "/camera/" + names_[k], cv::IMREAD_UNCHANGED);
    cv::Mat bgr8;
    png.convertTo(bgr8, CV_8U, 1.0 / 257);
    char name[32], time[64];
    std::snprintf(name, sizeof name, "DSC_%04zu.JPG", names_.size() - k);  // reversed
    std::snprintf(time, sizeof time, "2026:11:30 10:%02zu:00", k);
    exif.date_time = time;
    WriteJpeg(root_ + "/jpeg/" + name, bgr8, 95, exif);
    jpegs.push_back(name);
  }
  fs::copy_file(root_ + "/camera/BOARD.PNG", root_ + "/jpeg/BOARD.PNG");
  Ok("lumislab-acquire", "import --photos jpeg --setup setup.json --out ds --order capture");
  const Dataset imported = Dataset::Load(root_ + "/ds");
  ASSERT_EQ(imported.photos.size(), names_.size());
  for (const PhotoEntry& e : imported.photos) {
    EXPECT_NEAR(e.exposure, (1.0 / 30) * 200 / 64, 1e-9) << e.file;
    // The k-th photo taken is jpegs[k]; its place in the capture is that of names_[k].
    const size_t k = size_t(std::find(jpegs.begin(), jpegs.end(), e.file) - jpegs.begin());
    ASSERT_LT(k, names_.size());
    EXPECT_EQ(e.positive, k % 2 == 0) << e.file;
    EXPECT_EQ(std::make_pair(e.i, e.j), ScanPosition(ds.grid, "rows", int(k / 2))) << e.file;
  }
  // Name order is not the capture order, and the EXIF times say so: --order name is refused
  // naming the first pair taken the other way round (order.names_and_times), nothing written.
  // (By name DSC_0001, taken last, comes first: DSC_0002 is the first photo taken before the one
  // named before it.)
  const auto n =
      RunToolIn(root_, "lumislab-acquire",
                "import --photos jpeg --setup setup.json --out by_name --order name", 60);
  EXPECT_EQ(n.exit_code, 2) << n.output;
  for (const std::string& part : {"jpeg/" + jpegs[10] + ": EXIF DateTimeOriginal",
                                  "taken after " + jpegs[11], std::string("--order capture")})
    EXPECT_NE(n.output.find(part), std::string::npos) << part << "\n" << n.output;
  EXPECT_FALSE(fs::exists(root_ + "/by_name"));
  // --order capture records the names' disagreement as a warning (a counter that wrapped).
  const std::string checks = ReadBinaryFile(root_ + "/ds/checks.json");
  EXPECT_NE(checks.find("order.names_and_times"), std::string::npos) << checks;
  EXPECT_NE(checks.find("\"warning\""), std::string::npos) << checks;

  // Another camera model among them.
  exif.model = "Synthetic 2";
  const cv::Mat grey(240, 320, CV_8UC3, cv::Scalar(20, 20, 20));
  WriteJpeg(root_ + "/jpeg/" + jpegs[5], grey, 95, exif);
  const auto r = RunToolIn(root_, "lumislab-acquire",
                           "import --photos jpeg --setup setup.json --out ds2 --order capture", 60);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("jpeg/" + jpegs[5] + ": EXIF camera model: expected \"Synthetic 1\""),
            std::string::npos)
      << r.output;
  // No capture time.
  WriteJpeg(root_ + "/jpeg/" + jpegs[5], grey, 95, PhotoExif{});
  const auto t = RunToolIn(root_, "lumislab-acquire",
                           "import --photos jpeg --setup setup.json --out ds2 --order capture", 60);
  EXPECT_EQ(t.exit_code, 2) << t.output;
  EXPECT_NE(t.output.find("jpeg/" + jpegs[5] + ": EXIF DateTimeOriginal"), std::string::npos)
      << t.output;
  EXPECT_FALSE(fs::exists(root_ + "/ds2/dataset.json"));
}

// --partial: a capture that stopped early (order) or a manifest without a position gives a
// dataset listing the positions it lacks, with a warning naming them; without --partial the
// same folder is refused (BadFoldersAndDescriptionsAreRefused).
TEST_F(Import, PartialListsTheMissingPositions) {
  // The last position's two photos were never taken.
  for (size_t k = names_.size() - 2; k < names_.size(); ++k)
    fs::rename(root_ + "/camera/" + names_[k], root_ + "/" + names_[k]);
  const auto r = RunToolIn(root_, "lumislab-acquire",
                           "import --photos camera --setup setup.json --out ds --order name "
                           "--exposure 1 --partial",
                           60);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("partial dataset: 1 position(s) missing ((2, 1))"), std::string::npos)
      << r.output;
  const Dataset ds = Dataset::Load(root_ + "/ds");
  EXPECT_EQ(ds.photos.size(), 10u);
  EXPECT_EQ(ds.missing_positions, (std::vector<std::pair<int, int>>{{2, 1}}));
  // A manifest without position (1, 0), and with one slide only of (0, 1): both missing; the
  // lone photo is left out (and named among the unused files).
  for (size_t k = names_.size() - 2; k < names_.size(); ++k)
    fs::rename(root_ + "/" + names_[k], root_ + "/camera/" + names_[k]);
  std::string manifest;
  std::istringstream rows(manifest_);
  for (std::string row; std::getline(rows, row);)
    if (row.rfind("1,0,", 0) != 0 && row.rfind("0,1,n", 0) != 0) manifest += row + "\n";
  testing::WriteFile(root_ + "/partial.csv", manifest);
  Ok("lumislab-acquire",
     "import --photos camera --setup setup.json --out ds2 --manifest partial.csv --partial");
  EXPECT_EQ(Dataset::Load(root_ + "/ds2").missing_positions,
            (std::vector<std::pair<int, int>>{{1, 0}, {0, 1}}));
}

TEST(ImportScan, ScanOrders) {
  SamplingGrid grid;
  grid.nu = 3;
  grid.nv = 2;
  const std::vector<std::pair<int, int>> rows = {{0, 0}, {1, 0}, {2, 0}, {0, 1}, {1, 1}, {2, 1}};
  const std::vector<std::pair<int, int>> serpentine = {{0, 0}, {1, 0}, {2, 0},
                                                       {2, 1}, {1, 1}, {0, 1}};
  const std::vector<std::pair<int, int>> columns = {{0, 0}, {0, 1}, {1, 0}, {1, 1}, {2, 0}, {2, 1}};
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(ScanPosition(grid, "rows", k), rows[size_t(k)]);
    EXPECT_EQ(ScanPosition(grid, "serpentine", k), serpentine[size_t(k)]);
    EXPECT_EQ(ScanPosition(grid, "columns", k), columns[size_t(k)]);
  }
}

// A photo folder named in Latin-1 (an old camera card, a file server): dataset.json, which is
// JSON and so UTF-8, cannot name it; exit 2 naming dataset.json, the field and the name, nothing
// written. The same name in UTF-8 is imported.
TEST_F(Import, FolderNameThatIsNotUtf8IsRefusedNamingIt) {
  fs::rename(root_ + "/camera", root_ + "/cam\xe9ra");
  const auto before = SnapshotTree(root_);
  auto r = RunToolIn(root_, "lumislab-acquire",
                     "import --photos 'cam\xe9ra' --setup setup.json --out ds --order name "
                     "--exposure 1",
                     60);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  for (const char* name : {"ds/dataset.json: photo_folder", "cam\\xE9ra", "UTF-8"})
    EXPECT_NE(r.output.find(name), std::string::npos) << name << "\n" << r.output;
  EXPECT_EQ(r.output.find("json.exception"), std::string::npos) << r.output;
  EXPECT_EQ(testing::DiffSnapshots(before, SnapshotTree(root_)), std::vector<std::string>{});
  fs::rename(root_ + "/cam\xe9ra", root_ + "/cam\xc3\xa9ra");
  r = RunToolIn(root_, "lumislab-acquire",
                "import --photos 'cam\xc3\xa9ra' --setup setup.json --out ds --order name "
                "--exposure 1",
                60);
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

TEST_F(Import, BadFoldersAndDescriptionsAreRefused) {
  // A photo missing from the folder: the count and the first missing position.
  fs::rename(root_ + "/camera/" + names_.back(), root_ + "/" + names_.back());
  Refused("--order name --exposure 1", {"camera", "photos", "position (2, 1)"});
  fs::rename(root_ + "/" + names_.back(), root_ + "/camera/" + names_.back());
  // A file that is not an image, where a photo should be.
  testing::WriteFile(root_ + "/camera/" + names_[3], "not an image\n");
  Refused("--manifest captures.csv", {"camera/" + names_[3]});
  Refused("--order name --exposure 1", {"camera/" + names_[3]});
  fs::copy_file(root_ + "/camera/" + names_[2], root_ + "/camera/" + names_[3],
                fs::copy_options::overwrite_existing);
  // Manifest rows: a bad slide, a position outside the grid, a missing slide, a row twice.
  testing::WriteFile(root_ + "/bad.csv", "0,0,q," + names_[0] + ",1\n");
  Refused("--manifest bad.csv", {"bad.csv", "line 1, column slide"});
  testing::WriteFile(root_ + "/bad.csv", "5,0,p," + names_[0] + ",1\n");
  Refused("--manifest bad.csv", {"bad.csv: line 1", "position"});
  testing::WriteFile(root_ + "/bad.csv",
                     manifest_.substr(0, manifest_.rfind('\n', manifest_.size() - 2) + 1));
  Refused("--manifest bad.csv", {"bad.csv: rows", "slide n", "position (2, 1)"});
  testing::WriteFile(root_ + "/bad.csv", manifest_ + manifest_.substr(0, manifest_.find('\n') + 1));
  Refused("--manifest bad.csv",
          {"bad.csv: line 13", names_[0] + ", named before by bad.csv: line 1"});
  // Not a manifest: 17 MiB without a line end (read whole, its first line would be all of it).
  testing::WriteFile(root_ + "/bad.csv", std::string(17 << 20, 'x'));
  Refused("--manifest bad.csv", {"bad.csv", "size", "16 MiB"});
  // No exposure anywhere.
  testing::WriteFile(root_ + "/bad.csv", "0,0,p," + names_[0] + "\n");
  Refused("--manifest bad.csv", {"bad.csv: line 1", "no exposure"});
  Refused("--order name", {names_[0], "no exposure"});
  // Incomplete brackets: two exposures per slide announced, the folder holds one.
  Refused("--order name --exposures 1,4", {"camera", "24 photos"});
  // The options themselves.
  Refused("--order name --manifest captures.csv --exposure 1", {"exactly one of"});
  Refused("--pattern IMG_{i}.PNG --exposure 1", {"--pattern", "{j}"});
  Refused("--order time --exposure 1", {"--order"});
  Refused("--order name --scan spiral --exposure 1", {"--scan"});
  // The setup file and the board photo.
  Refused("--order name --exposure 1 --setup nothere.json", {"nothere.json"});
  nlohmann::json setup = nlohmann::json::parse(ReadBinaryFile(root_ + "/setup.json"));
  setup["calibration"]["photo"] = "NOBOARD.PNG";
  testing::WriteFile(root_ + "/setup2.json", setup.dump());
  Refused("--order name --exposure 1 --setup setup2.json", {"camera/NOBOARD.PNG"});
}

}  // namespace
}  // namespace lumislab
