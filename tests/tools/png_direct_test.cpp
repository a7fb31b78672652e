// The direct PNG decoder (tools/dataset/png_direct.hpp) against OpenCV's imread (libpng) on
// PNGs built here chunk by chunk, so that every filter type, several IDAT chunks and each
// reason to leave a file to libpng are covered; and its row unfiltering against the PNG
// specification's formulas written out per byte.

#include "tools/dataset/png_direct.hpp"

#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "tests/tools/temp_dir.hpp"
#include "tools/dataset/image_file.hpp"
#include "tools/dataset/input_error.hpp"

namespace parallax {
namespace {

using Bytes = std::vector<std::uint8_t>;
using codecs::DecodeCommonPng;
using test::TempDir;

/// The PNG specification's predictor for filter `type` (9.2-9.4), byte by byte.
int Predictor(int type, int a, int b, int c) {
  switch (type) {
    case 1:
      return a;
    case 2:
      return b;
    case 3:
      return (a + b) / 2;
    case 4: {
      const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
      if (pa <= pb && pa <= pc) return a;
      return pb <= pc ? b : c;
    }
    default:
      return 0;
  }
}

/// Filters `row` (raw pixels) against `previous` with `type`, as an encoder would.
Bytes FilterRow(int type, const Bytes& row, const Bytes& previous, std::size_t bpp) {
  Bytes out(row.size());
  for (std::size_t i = 0; i < row.size(); ++i) {
    const bool left = i >= bpp;
    const int a = left ? row[i - bpp] : 0, b = previous[i], c = left ? previous[i - bpp] : 0;
    out[i] = static_cast<std::uint8_t>(row[i] - Predictor(type, a, b, c));
  }
  return out;
}

void PutBigEndian(std::uint32_t v, Bytes* out) {
  for (const int shift : {24, 16, 8, 0}) out->push_back(static_cast<std::uint8_t>(v >> shift));
}

void AddChunk(const char* type, const Bytes& data, Bytes* png, bool break_crc = false) {
  PutBigEndian(static_cast<std::uint32_t>(data.size()), png);
  Bytes typed(type, type + 4);
  typed.insert(typed.end(), data.begin(), data.end());
  png->insert(png->end(), typed.begin(), typed.end());
  const auto crc =
      static_cast<std::uint32_t>(crc32(0, typed.data(), static_cast<uInt>(typed.size())));
  PutBigEndian(break_crc ? crc ^ 1U : crc, png);
}

/// How a test PNG is built; the defaults make one the direct decoder handles.
struct PngRecipe {
  int width = 37;
  int height = 23;
  int colour_type = 0;  ///< 0 grey, 2 RGB
  int bit_depth = 8;
  int interlace = 0;
  int first_filter = 0;                   ///< row y uses filter (first_filter + y) % 5 ...
  int bad_filter_row = -1;                ///< ... except this row, which gets type 5
  std::size_t idat_size = 97;             ///< the stream split into chunks of this size
  std::vector<std::string> extra_chunks;  ///< ancillary chunks (empty data) before IDAT
  bool break_idat_crc = false;
  int extra_inflated_bytes = 0;  ///< rows padded (+) or cut (-) before compression
  bool end_chunk = true;
  bool grey_equal_pixels = false;  ///< RGB pixels with r = g = b every other pixel
};

Bytes BuildPng(const PngRecipe& r, std::uint32_t seed) {
  const std::size_t bpp = r.colour_type == 2 ? 3 : 1;
  const std::size_t row_bytes = static_cast<std::size_t>(r.width) * bpp;
  std::mt19937 rng(seed);
  Bytes stream, previous(row_bytes, 0);
  for (int y = 0; y < r.height; ++y) {
    Bytes row(row_bytes);
    for (auto& v : row) v = static_cast<std::uint8_t>(rng());
    if (r.grey_equal_pixels && bpp == 3) {
      for (std::size_t x = 0; x < row_bytes; x += 6) row[x + 1] = row[x + 2] = row[x];
    }
    const int type = y == r.bad_filter_row ? 5 : (r.first_filter + y) % 5;
    stream.push_back(static_cast<std::uint8_t>(type));
    const Bytes filtered = FilterRow(type % 5, row, previous, bpp);
    stream.insert(stream.end(), filtered.begin(), filtered.end());
    previous = row;
  }
  if (r.extra_inflated_bytes > 0) {
    stream.insert(stream.end(), static_cast<std::size_t>(r.extra_inflated_bytes), 0);
  } else {
    stream.resize(stream.size() - static_cast<std::size_t>(-r.extra_inflated_bytes));
  }
  uLongf packed_size = compressBound(static_cast<uLong>(stream.size()));
  Bytes packed(packed_size);
  EXPECT_EQ(
      compress2(packed.data(), &packed_size, stream.data(), static_cast<uLong>(stream.size()), 6),
      Z_OK);
  packed.resize(packed_size);
  Bytes png = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
  Bytes header;
  PutBigEndian(static_cast<std::uint32_t>(r.width), &header);
  PutBigEndian(static_cast<std::uint32_t>(r.height), &header);
  for (const int v : {r.bit_depth, r.colour_type, 0, 0, r.interlace}) {
    header.push_back(static_cast<std::uint8_t>(v));
  }
  AddChunk("IHDR", header, &png);
  for (const std::string& name : r.extra_chunks) AddChunk(name.c_str(), Bytes(4, 0), &png);
  for (std::size_t at = 0; at < packed.size(); at += r.idat_size) {
    const Bytes part(
        packed.begin() + static_cast<std::ptrdiff_t>(at),
        packed.begin() + static_cast<std::ptrdiff_t>(std::min(packed.size(), at + r.idat_size)));
    AddChunk("IDAT", part, &png, r.break_idat_crc);
  }
  if (r.end_chunk) AddChunk("IEND", {}, &png);
  return png;
}

std::string WriteFile(const TempDir& dir, const std::string& name, const Bytes& bytes) {
  std::string file = dir.File(name);
  std::ofstream(file, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
  return file;
}

bool Identical(const cv::Mat& a, const cv::Mat& b) {
  return a.type() == b.type() && a.size() == b.size() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

TEST(PngDirect, EachFilterTypeUnfiltersAsTheSpecificationSays) {
  std::mt19937 rng(5);
  for (const int bpp : {1, 3}) {
    for (const std::size_t row_bytes : {std::size_t{1}, std::size_t{3}, std::size_t{64 * 3 + 1}}) {
      for (int type = 0; type <= 4; ++type) {
        Bytes row(row_bytes), previous(row_bytes), out(row_bytes);
        for (auto& v : row) v = static_cast<std::uint8_t>(rng());
        for (auto& v : previous) v = static_cast<std::uint8_t>(rng());
        const Bytes filtered = FilterRow(type, row, previous, static_cast<std::size_t>(bpp));
        ASSERT_TRUE(codecs::UnfilterPngRow(type, filtered.data(), previous.data(), row_bytes, bpp,
                                           out.data()));
        EXPECT_EQ(out, row) << "filter " << type << ", " << bpp << " bytes a pixel";
      }
    }
  }
  Bytes b(4), out(4);
  EXPECT_FALSE(codecs::UnfilterPngRow(5, b.data(), b.data(), 4, 1, out.data()));
}

TEST(PngDirect, GreyAndRgbPngsDecodeAsOpenCvsGreyscaleRead) {
  const TempDir dir;
  int n = 0;
  for (const int colour_type : {0, 2}) {
    for (const int first_filter : {0, 1, 2, 3, 4}) {
      PngRecipe r;
      r.colour_type = colour_type;
      r.first_filter = first_filter;
      r.grey_equal_pixels = first_filter % 2 == 0;
      r.extra_chunks =
          first_filter == 3 ? std::vector<std::string>{"tEXt", "pHYs"} : std::vector<std::string>{};
      r.idat_size = first_filter == 1 ? 1 << 20 : 97;  // one IDAT, or many
      const Bytes png = BuildPng(r, static_cast<std::uint32_t>(n));
      const std::string file = WriteFile(dir, "p" + std::to_string(n++) + ".png", png);
      const auto direct = DecodeCommonPng(png.data(), png.size(), 1 << 20);
      ASSERT_TRUE(direct.has_value()) << file;
      const cv::Mat reference = cv::imread(file, cv::IMREAD_GRAYSCALE);
      EXPECT_TRUE(Identical(*direct, reference)) << file;
      EXPECT_TRUE(Identical(ReadImageFile(file, ImageReadMode::kGrey8), reference)) << file;
    }
  }
}

TEST(PngDirect, PngsFromLibpngsWriterDecodeAsOpenCvsGreyscaleRead) {
  const TempDir dir;
  std::mt19937 rng(3);
  for (const int channels : {1, 3}) {
    cv::Mat image(120, 160, CV_8UC(channels));
    cv::randu(image, 0, 256);
    cv::Mat smooth;  // real frames are smooth: libpng's writer then picks varied filters
    cv::blur(image, smooth, cv::Size(9, 9));
    for (const cv::Mat& m : {image, smooth}) {
      const std::string file = dir.File("w" + std::to_string(rng()) + ".png");
      ASSERT_TRUE(cv::imwrite(file, m));
      std::ifstream in(file, std::ios::binary);
      const Bytes bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      const auto direct = DecodeCommonPng(bytes.data(), bytes.size(), 1 << 20);
      ASSERT_TRUE(direct.has_value()) << file;
      EXPECT_TRUE(Identical(*direct, cv::imread(file, cv::IMREAD_GRAYSCALE))) << file;
    }
  }
}

TEST(PngDirect, UnusualOrDamagedFilesAreLeftToLibpng) {
  const TempDir dir;
  std::vector<std::pair<std::string, PngRecipe>> cases;
  const auto add = [&](const std::string& name, auto change) {
    PngRecipe r;
    change(&r);
    cases.emplace_back(name, r);
  };
  add("16-bit", [](PngRecipe* r) { r->bit_depth = 16; });
  add("interlaced", [](PngRecipe* r) { r->interlace = 1; });
  add("gamma chunk", [](PngRecipe* r) { r->extra_chunks = {"gAMA"}; });
  add("sRGB chunk", [](PngRecipe* r) { r->extra_chunks = {"sRGB"}; });
  add("unknown chunk", [](PngRecipe* r) { r->extra_chunks = {"abCd"}; });
  add("bad CRC", [](PngRecipe* r) { r->break_idat_crc = true; });
  add("bad filter type", [](PngRecipe* r) { r->bad_filter_row = 7; });
  add("rows too short", [](PngRecipe* r) { r->extra_inflated_bytes = -5; });
  add("rows too long", [](PngRecipe* r) { r->extra_inflated_bytes = 40; });
  add("no IEND", [](PngRecipe* r) { r->end_chunk = false; });
  for (const auto& [name, recipe] : cases) {
    const Bytes png = BuildPng(recipe, 1);
    EXPECT_FALSE(DecodeCommonPng(png.data(), png.size(), 1 << 20).has_value()) << name;
    // libpng decodes it as OpenCV does, or it is refused naming the file.
    const std::string file = WriteFile(dir, "u.png", png);
    const cv::Mat reference = cv::imread(file, cv::IMREAD_GRAYSCALE);
    try {
      const cv::Mat ours = ReadImageFile(file, ImageReadMode::kGrey8);
      EXPECT_TRUE(Identical(ours, reference)) << name;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("u.png"), std::string::npos) << name;
    }
  }
  PngRecipe large;
  const Bytes png = BuildPng(large, 2);
  EXPECT_FALSE(DecodeCommonPng(png.data(), png.size(), 37 * 23 - 1).has_value());
  EXPECT_TRUE(DecodeCommonPng(png.data(), png.size(), 37 * 23).has_value());
  const Bytes cut(png.begin(), png.begin() + static_cast<std::ptrdiff_t>(png.size() / 2));
  EXPECT_FALSE(DecodeCommonPng(cut.data(), cut.size(), 1 << 20).has_value());
}

TEST(PngDirect, GreyWeightsAreLibpngsFixedPointOnes) {
  // png_set_rgb_to_gray(0.299, 0.587): PNG fixed point 29900 and 58700, times 32768 / 1e5,
  // truncated; blue the rest of 32768.
  EXPECT_EQ(codecs::kPngGreyRed, 9797U);
  EXPECT_EQ(codecs::kPngGreyGreen, 19234U);
  EXPECT_EQ(codecs::kPngGreyBlue, 3737U);
}

}  // namespace
}  // namespace parallax
