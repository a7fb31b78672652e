// The PNG and JPEG codecs (tools/dataset/image_file.hpp) against OpenCV's imread on the same
// files: the pixels must be the same as before the readers stopped linking OpenCV's codecs.
// Also the media module (videos, other formats), which this executable's OpenCV writes for.

#include "tools/dataset/image_file.hpp"

#include <gtest/gtest.h>
#include <zlib.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <random>
#include <vector>

#include "tests/tools/temp_dir.hpp"
#include "tools/dataset/dataset_reader.hpp"
#include "tools/dataset/file_list_reader.hpp"
#include "tools/dataset/input_error.hpp"

namespace parallax {
namespace {

using test::SharedDataDir;
using test::TempDir;

bool Identical(const cv::Mat& a, const cv::Mat& b) {
  return a.type() == b.type() && a.size() == b.size() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

/// A test pattern with every value of the depth's range, in `channels` channels.
cv::Mat Pattern(int depth, int channels) {
  cv::Mat m(37, 53, CV_MAKETYPE(depth, channels));
  cv::randu(m, 0, depth == CV_16U ? 65536 : 256);
  return m;
}

void ExpectSameAsOpenCv(const std::string& file) {
  const cv::Mat grey = cv::imread(file, cv::IMREAD_GRAYSCALE);
  const cv::Mat unchanged = cv::imread(file, cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(grey.empty()) << file;
  EXPECT_TRUE(Identical(ReadImageFile(file, ImageReadMode::kGrey8), grey)) << file;
  EXPECT_TRUE(Identical(ReadImageFile(file, ImageReadMode::kUnchanged), unchanged)) << file;
  EXPECT_EQ(ProbeImageFile(file), grey.size()) << file;
}

TEST(ImageFile, PngOfEveryDepthAndChannelCountDecodesAsOpenCvDoes) {
  const TempDir dir;
  int n = 0;
  for (const int depth : {CV_8U, CV_16U}) {
    for (const int channels : {1, 3, 4}) {
      const std::string file = dir.File("p" + std::to_string(n++) + ".png");
      ASSERT_TRUE(cv::imwrite(file, Pattern(depth, channels)));
      ExpectSameAsOpenCv(file);
    }
  }
  const std::string bilevel = dir.File("bilevel.png");  // 1-bit grey
  ASSERT_TRUE(cv::imwrite(bilevel, Pattern(CV_8U, 1) > 128, {cv::IMWRITE_PNG_BILEVEL, 1}));
  ExpectSameAsOpenCv(bilevel);
}

TEST(ImageFile, JpegInGreyAndColourDecodesAsOpenCvDoes) {
  const TempDir dir;
  cv::Mat smooth(48, 64, CV_8UC3);
  for (int y = 0; y < smooth.rows; ++y) {
    for (int x = 0; x < smooth.cols; ++x) {
      smooth.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uchar>(4 * x), static_cast<uchar>(5 * y),
                                             static_cast<uchar>(2 * (x + y)));
    }
  }
  for (const int quality : {50, 95}) {
    const std::string colour = dir.File("c" + std::to_string(quality) + ".jpg");
    const std::string grey = dir.File("g" + std::to_string(quality) + ".jpg");
    ASSERT_TRUE(cv::imwrite(colour, smooth, {cv::IMWRITE_JPEG_QUALITY, quality}));
    cv::Mat smooth_grey;
    cv::extractChannel(smooth, smooth_grey, 1);
    ASSERT_TRUE(cv::imwrite(grey, smooth_grey, {cv::IMWRITE_JPEG_QUALITY, quality}));
    ExpectSameAsOpenCv(colour);
    ExpectSameAsOpenCv(grey);
  }
}

TEST(ImageFile, RealClipsDecodeAsOpenCvDoes) {
  const std::string tum = SharedDataDir() + "/rgbd_dataset_freiburg1_xyz_first37/rgb";
  const std::string kitti = SharedDataDir() + "/kitti_odometry_07_first160/sequences/07/image_0";
  if (!std::filesystem::exists(tum) || !std::filesystem::exists(kitti)) GTEST_SKIP();
  int checked = 0;
  for (const std::string& folder : {tum, kitti}) {
    std::vector<std::filesystem::path> files(std::filesystem::directory_iterator(folder), {});
    std::sort(files.begin(), files.end());
    for (std::size_t i = 0; i < files.size(); ++i, ++checked) {
      ExpectSameAsOpenCv(files[i].string());  // TUM: colour PNGs read as grey
    }
  }
  EXPECT_EQ(checked, 37 + 160);
}

TEST(ImageFile, WrittenPngReadsBackExactly) {
  const TempDir dir;
  for (const int depth : {CV_8U, CV_16U}) {
    for (const int channels : {1, 3}) {
      const cv::Mat m = Pattern(depth, channels);
      const std::string file =
          dir.File("w" + std::to_string(depth) + std::to_string(channels) + ".png");
      WritePngFile(file, m, 1);
      EXPECT_TRUE(Identical(cv::imread(file, cv::IMREAD_UNCHANGED), m));
      EXPECT_TRUE(Identical(ReadImageFile(file, ImageReadMode::kUnchanged), m));
    }
  }
  EXPECT_THROW(WritePngFile(dir.File("no/such/folder/a.png"), Pattern(CV_8U, 1)), InputError);
  EXPECT_THROW(WritePngFile(dir.File("f.png"), cv::Mat(4, 4, CV_32FC1)), InputError);
}

std::string ReadBytes(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void WriteBytes(const std::string& file, const std::string& bytes) {
  std::ofstream(file, std::ios::binary) << bytes;
}

void ExpectInputErrorNaming(const std::string& file) {
  try {
    (void)ReadImageFile(file, ImageReadMode::kGrey8);
    ADD_FAILURE() << file << " was decoded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
  }
}

TEST(ImageFile, CorruptTruncatedAndHugeFilesAreRefusedNamingTheFile) {
  const TempDir dir;
  const std::string png = dir.File("a.png");
  ASSERT_TRUE(cv::imwrite(png, Pattern(CV_8U, 1)));
  const std::string bytes = ReadBytes(png);
  // Truncated in the pixel data: OpenCV fails too.
  const std::string truncated = dir.File("truncated.png");
  WriteBytes(truncated, bytes.substr(0, bytes.size() / 2));
  EXPECT_TRUE(cv::imread(truncated, cv::IMREAD_GRAYSCALE).empty());
  ExpectInputErrorNaming(truncated);
  EXPECT_EQ(ProbeImageFile(truncated), cv::Size(53, 37));  // the header is intact
  // A header claiming 2^20 x 2^20 pixels (CRC fixed): refused before any allocation.
  std::string huge = bytes;
  for (const std::size_t offset : {16U, 20U}) {  // IHDR width, height (big-endian)
    huge.replace(offset, 4, std::string("\0\x10\0\0", 4));
  }
  const auto crc =
      static_cast<std::uint32_t>(crc32(0, reinterpret_cast<const Bytef*>(huge.data() + 12), 17));
  for (std::size_t i = 0; i < 4; ++i)
    huge[29 + i] = static_cast<char>((crc >> (24 - 8 * i)) & 0xffU);
  const std::string huge_file = dir.File("huge.png");
  WriteBytes(huge_file, huge);
  ExpectInputErrorNaming(huge_file);
  EXPECT_THROW(ReadGreyImage(huge_file, 53, 37), InputError);
  // Garbage after a JPEG's first bytes.
  const std::string jpeg = dir.File("garbage.jpg");
  WriteBytes(jpeg, std::string("\xff\xd8\xff\xe0", 4) + std::string(200, 'x'));
  ExpectInputErrorNaming(jpeg);
}

std::string ReadGreyImageError(const std::string& file, int width, int height) {
  try {
    (void)ReadGreyImage(file, width, height);
  } catch (const InputError& e) {
    return e.what();
  }
  return "decoded";
}

TEST(ReadGreyImage, AFrameOfAnotherSizeIsRefusedSayingBothSizes) {
  const TempDir dir;
  const std::string png = dir.File("a.png");
  ASSERT_TRUE(cv::imwrite(png, Pattern(CV_8U, 1)));  // 53 x 37
  EXPECT_EQ(ReadGreyImage(png, 53, 37).Width(), 53);
  // Fewer pixels than the file's: refused from the header; more: decoded, then refused.
  for (const cv::Size camera : {cv::Size(40, 30), cv::Size(60, 40), cv::Size(37, 53)}) {
    const std::string error = ReadGreyImageError(png, camera.width, camera.height);
    EXPECT_NE(error.find(png), std::string::npos) << error;
    EXPECT_NE(error.find("image is 53x37 but the camera is " + std::to_string(camera.width) + "x" +
                         std::to_string(camera.height)),
              std::string::npos)
        << error;
  }
  // A file whose header is right but whose pixels are cut off keeps the decoder's error.
  const std::string bytes = ReadBytes(png);
  const std::string truncated = dir.File("truncated.png");
  WriteBytes(truncated, bytes.substr(0, bytes.size() / 2));
  const std::string error = ReadGreyImageError(truncated, 53, 37);
  EXPECT_NE(error.find(truncated), std::string::npos) << error;
  EXPECT_EQ(error.find("but the camera is"), std::string::npos) << error;
  EXPECT_NE(error, "decoded");
}

// Fuzzing in miniature (tests/fuzz/fuzz_image does it at length): corrupted PNG and JPEG
// files either decode to an image of a plausible size or are refused with an InputError.
TEST(ImageFile, CorruptedBytesAreDecodedOrRefusedNeverCrash) {
  const TempDir dir;
  cv::Mat colour = Pattern(CV_8U, 3);
  cv::GaussianBlur(colour, colour, cv::Size(5, 5), 2.0);
  const std::string png = dir.File("a.png"), jpeg = dir.File("a.jpg");
  ASSERT_TRUE(cv::imwrite(png, colour));
  ASSERT_TRUE(cv::imwrite(jpeg, colour));
  std::mt19937 rng(11);
  int decoded = 0, refused = 0;
  for (const std::string& original : {png, jpeg}) {
    const std::string bytes = ReadBytes(original);
    for (int trial = 0; trial < 400; ++trial) {
      std::string corrupted = bytes;
      std::uniform_int_distribution<std::size_t> position(2, bytes.size() - 1);
      for (int k = 0; k < 1 + trial % 8; ++k) {
        corrupted[position(rng)] = static_cast<char>(rng() & 0xffU);
      }
      if (trial % 5 == 0) corrupted.resize(position(rng));
      const std::string file = dir.File("c" + std::filesystem::path(original).extension().string());
      WriteBytes(file, corrupted);
      for (const ImageReadMode mode : {ImageReadMode::kGrey8, ImageReadMode::kUnchanged}) {
        try {
          const cv::Mat m = ReadImageFile(file, mode, 1 << 20);
          EXPECT_LE(static_cast<long long>(m.cols) * m.rows, 1 << 20);
          ++decoded;
        } catch (const InputError&) {
          ++refused;
        }
      }
    }
  }
  EXPECT_GT(decoded, 0);
  EXPECT_GT(refused, 0);
}

TEST(ImageFile, OtherFormatsGoThroughTheMediaModule) {
  const TempDir dir;
  const cv::Mat m = Pattern(CV_8U, 3);
  for (const std::string name : {"a.bmp", "a.tiff", "a.ppm"}) {
    ASSERT_TRUE(cv::imwrite(dir.File(name), m));
    ExpectSameAsOpenCv(dir.File(name));
  }
}

TEST(VideoReader, ReadsFramesWithCalibration) {
  TempDir dir;
  const std::string video = dir.File("clip.avi");
  cv::VideoWriter writer(video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25.0, cv::Size(64, 48),
                         false);
  if (!writer.isOpened()) GTEST_SKIP() << "this OpenCV build cannot write MJPG video";
  for (int i = 0; i < 5; ++i) writer.write(cv::Mat(48, 64, CV_8UC1, cv::Scalar(40 * i)));
  writer.release();
  EXPECT_THROW(OpenDataset(video), InputError);  // no calibration yet
  dir.Write("clip.yaml",
            "model: pinhole\nwidth: 64\nheight: 48\nfx: 50\nfy: 50\ncx: 31.5\ncy: 23.5\n");
  const auto reader = OpenDataset(video);
  EXPECT_EQ(reader->Format(), DatasetFormat::kVideo);
  int count = 0;
  double last = -1.0;
  while (auto f = reader->Next()) {
    EXPECT_GT(f->timestamp, last);
    last = f->timestamp;
    EXPECT_NEAR(f->image(10, 10), 40 * count, 6);
    ++count;
  }
  EXPECT_EQ(count, 5);
}

}  // namespace
}  // namespace parallax
