// Zarr v2 store writer: the files a Zarr reader expects, checked against the format's rules computed here
// independently (chunk grid, C order, edge padding with the fill value, metadata), and the store's safety
// (complete or absent, afmkit stores replaced, anything else refused).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <unistd.h>

#include "afmkit/core/error.hpp"
#include "afmkit/io/zarr_store.hpp"

namespace fs = std::filesystem;
using afmkit::io::ZarrStoreWriter;

namespace {

struct Dir {
  fs::path path = fs::temp_directory_path() / ("afmkit-zarr-test-" + std::to_string(::getpid()) + "-" +
                                               ::testing::UnitTest::GetInstance()->current_test_info()->name());
  Dir() { fs::remove_all(path), fs::create_directories(path); }
  ~Dir() { fs::remove_all(path); }
};

std::vector<unsigned char> bytes(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}
nlohmann::json json_of(const fs::path& f) { return nlohmann::json::parse(bytes(f)); }

std::vector<double> doubles(const fs::path& f) {
  const auto b = bytes(f);
  std::vector<double> v(b.size() / 8);
  std::memcpy(v.data(), b.data(), v.size() * 8);
  return v;
}

}  // namespace

TEST(ZarrStore, ChunksAreCOrderBlocksPaddedWithTheFillValue) {
  Dir dir;
  const fs::path store = dir.path / "s.zarr";
  // a 5 x 3 array, value 10 i + j, in 2 x 2 chunks: a 3 x 2 chunk grid with partial edge chunks
  std::vector<double> values;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 3; ++j) values.push_back(10.0 * i + j);
  ZarrStoreWriter w(store.string(), "store");
  w.attribute("afmkit_study_format", 1);
  w.coordinate("x", {0.0, 1.0, 2.0, 3.0, 4.0}, {{"units", "nm"}});
  w.coordinate("y", {-1.0, 0.0, 1.0}, {{"units", "rad"}});
  w.variable("v", {"x", "y"}, {5, 3}, {2, 2}, values, {{"units", "nN"}});
  w.integer_variable("done", {"chunk"}, {3}, {1}, {1, 0, 1}, "<i1", {});
  w.commit();

  for (int ci = 0; ci < 3; ++ci)
    for (int cj = 0; cj < 2; ++cj) {
      const auto chunk = doubles(store / "v" / (std::to_string(ci) + "." + std::to_string(cj)));
      ASSERT_EQ(chunk.size(), 4u) << "every chunk has the full chunk shape";
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
          const int i = 2 * ci + a, j = 2 * cj + b;
          const double got = chunk[2 * a + b];
          if (i < 5 && j < 3) {
            EXPECT_EQ(got, 10.0 * i + j) << i << "," << j;
          }
          else EXPECT_TRUE(std::isnan(got)) << "padding is the fill value NaN at " << i << "," << j;
        }
    }
  const auto zarray = json_of(store / "v" / ".zarray");
  EXPECT_EQ(zarray["shape"], nlohmann::json({5, 3}));
  EXPECT_EQ(zarray["chunks"], nlohmann::json({2, 2}));
  EXPECT_EQ(zarray["dtype"], "<f8");
  EXPECT_EQ(zarray["fill_value"], "NaN");
  EXPECT_EQ(zarray["order"], "C");
  EXPECT_TRUE(zarray["compressor"].is_null());
  EXPECT_EQ(json_of(store / "v" / ".zattrs")["_ARRAY_DIMENSIONS"], nlohmann::json({"x", "y"}));
  // coordinates: no fill value (0.0 must not read back as missing), dimension named after themselves
  EXPECT_TRUE(json_of(store / "y" / ".zarray")["fill_value"].is_null());
  EXPECT_EQ(doubles(store / "y" / "0"), (std::vector<double>{-1.0, 0.0, 1.0}));
  // integers: one byte each, chunk files "0", "1", "2"
  EXPECT_EQ(bytes(store / "done" / "1"), std::vector<unsigned char>{0});
  EXPECT_EQ(bytes(store / "done" / "2"), std::vector<unsigned char>{1});
  // consolidated metadata holds every .zarray/.zattrs as written
  const auto meta = json_of(store / ".zmetadata");
  EXPECT_EQ(meta["zarr_consolidated_format"], 1);
  EXPECT_EQ(meta["metadata"]["v/.zarray"], zarray);
  EXPECT_EQ(meta["metadata"][".zgroup"]["zarr_format"], 2);
  EXPECT_EQ(meta["metadata"][".zattrs"]["afmkit_study_format"], 1);
}

TEST(ZarrStore, AnAfmkitStoreIsReplacedAnythingElseRefusedBeforeComputing) {
  Dir dir;
  const fs::path store = dir.path / "s.zarr";
  for (double value : {1.0, 2.0}) {
    ZarrStoreWriter w(store.string(), "store");
    w.attribute("afmkit_study_format", 1);
    w.variable("v", {"x"}, {1}, {1}, {value}, {});
    w.commit();
    EXPECT_EQ(doubles(store / "v" / "0"), std::vector<double>{value});
  }
  for (const auto& e : fs::directory_iterator(dir.path))
    EXPECT_EQ(e.path().filename(), "s.zarr") << "left behind: " << e.path();
  fs::create_directories(dir.path / "photos");
  std::ofstream(dir.path / "photos" / "a.jpg") << "x";
  std::ofstream(dir.path / "file") << "x";
  for (const fs::path& bad : {dir.path / "photos", dir.path / "file", dir.path / "file" / "s.zarr", fs::path()}) {
    try {
      ZarrStoreWriter w(bad.string(), "store");
      ADD_FAILURE() << bad << " accepted";
    } catch (const afmkit::InvalidParameter& e) {
      EXPECT_EQ(e.parameter(), "store");
      EXPECT_NE(std::string(e.what()).find("cannot be written"), std::string::npos) << e.what();
    }
  }
  EXPECT_TRUE(fs::exists(dir.path / "photos" / "a.jpg"));
}
