// Photometric correction (TUM monoVO response and vignette): a gamma-encoded, vignetted flat
// field comes back flat and linear; bad calibrations are refused naming the problem; a
// rendered monoVO sequence with a response, vignette and exposure changes is read with its
// calibration and corrected.

#include "tools/dataset/photometric_corrector.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "temp_dir.hpp"
#include "tools/dataset/dataset_reader.hpp"
#include "tools/dataset/input_error.hpp"
#include "tools/synth/synthetic_sequence.hpp"

namespace parallax {
namespace {

/// G^-1 of the response grey = 255 (E / 255)^(1 / gamma).
std::vector<float> InverseGamma(double gamma) {
  std::vector<float> r(256);
  for (std::size_t i = 0; i < 256; ++i) {
    r[i] = static_cast<float>(255.0 * std::pow(static_cast<double>(i) / 255.0, gamma));
  }
  return r;
}

TEST(PhotometricCorrector, UndoesTheResponseAndTheVignette) {
  const int w = 64, h = 48;
  PhotometricCalibration calibration;
  calibration.inverse_response = InverseGamma(2.2);
  ImageF vignette(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) vignette(x, y) = 0.5f + 0.5f * static_cast<float>(x) / (w - 1);
  }
  calibration.vignette = vignette;
  const PhotometricCorrector corrector(calibration, w, h);
  ASSERT_TRUE(corrector.Enabled());
  // A flat field of irradiance 200, vignetted, then gamma-encoded.
  ImageU8 in(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double exposed = 200.0 * vignette(x, y);
      in(x, y) = static_cast<std::uint8_t>(std::lround(255.0 * std::pow(exposed / 255.0, 1 / 2.2)));
    }
  }
  ImageU8 out;
  corrector.Apply(in, &out);
  // Linear again and flat at 200 * v_ref (v_ref = 0.5, the smallest vignette value), within
  // the quantisation of the 8-bit encoding.
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) EXPECT_NEAR(out(x, y), 100, 2) << x << "," << y;
  }
  // In place, as the frame reader applies it.
  corrector.Apply(in, &in);
  EXPECT_EQ(in(5, 5), out(5, 5));
}

TEST(PhotometricCorrector, RefusesCalibrationsThatCannotBeRight) {
  const auto refused = [](const PhotometricCalibration& c, const std::string& fragment) {
    try {
      const PhotometricCorrector corrector(c, 8, 6);
      ADD_FAILURE() << "accepted: " << fragment;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  refused({std::vector<float>(255, 1.0f), std::nullopt}, "256 values");
  std::vector<float> decreasing = InverseGamma(2.0);
  decreasing[100] = 0.0f;
  refused({decreasing, std::nullopt}, "decreases at value 100");
  refused({std::vector<float>(256, 3.0f), std::nullopt}, "constant");
  std::vector<float> nan = InverseGamma(2.0);
  nan[7] = std::nanf("");
  refused({nan, std::nullopt}, "not finite");
  refused({{}, ImageF(9, 6, 1.0f)}, "the vignette is 9x6");
  refused({{}, ImageF(8, 6, 0.0f)}, "all zero");
  ImageF negative(8, 6, 1.0f);
  negative(2, 2) = -1.0f;
  refused({{}, negative}, ">= 0");
  EXPECT_FALSE(PhotometricCorrector(PhotometricCalibration{}, 8, 6).Enabled());
}

TEST(PhotometricCorrector, ARenderedMonoSequenceIsReadWithItsCalibration) {
  const test::TempDir dir;
  synth::SynthOptions o;
  o.frames = 3;
  o.width = 160;
  o.height = 120;
  o.vignette = true;
  o.exposure = true;
  o.response_gamma = 2.2;
  o.layout = "tum_mono";
  synth::WriteSyntheticSequence(o, dir.File("mono"));
  const auto reader = OpenDataset(dir.File("mono"), {});
  const std::optional<PhotometricCalibration> calibration = reader->Photometric();
  ASSERT_TRUE(calibration);
  ASSERT_EQ(calibration->inverse_response.size(), 256u);
  EXPECT_NEAR(calibration->inverse_response[128], 255.0 * std::pow(128 / 255.0, 2.2), 1e-3);
  ASSERT_TRUE(calibration->vignette);
  EXPECT_NEAR((*calibration->vignette)(80, 60), 1.0f, 0.01f);  // the centre
  EXPECT_LT((*calibration->vignette)(0, 0), 0.7f);
  const auto frame = reader->Next();
  ASSERT_TRUE(frame && frame->exposure_ms);
  EXPECT_GT(*frame->exposure_ms, 5.0);
  EXPECT_TRUE(reader->GroundTruth().has_value());
  // A broken pcalib.txt is refused when the dataset is opened, naming the file.
  dir.Write("mono/pcalib.txt", "1 2 3\n");
  try {
    OpenDataset(dir.File("mono"), {});
    ADD_FAILURE() << "a 3-value response was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pcalib.txt"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace parallax
