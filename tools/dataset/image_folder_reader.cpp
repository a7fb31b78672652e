// A plain folder of images (natural sort) with a calibration YAML and optional times.txt
// (docs/datasets.md).

#include <algorithm>
#include <filesystem>

#include "tools/dataset/calibration_yaml.hpp"
#include "tools/dataset/file_list_reader.hpp"
#include "tools/dataset/input_error.hpp"
#include "tools/dataset/text_lines.hpp"

namespace fs = std::filesystem;

namespace parallax {

bool IsImageFile(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".pgm" || ext == ".bmp" ||
         ext == ".tif" || ext == ".tiff";
}

/// "img2.png" < "img10.png": digit runs compare by value.
bool NaturalLess(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) &&
        std::isdigit(static_cast<unsigned char>(b[j]))) {
      std::size_t i_end = i, j_end = j;
      while (i_end < a.size() && std::isdigit(static_cast<unsigned char>(a[i_end]))) ++i_end;
      while (j_end < b.size() && std::isdigit(static_cast<unsigned char>(b[j_end]))) ++j_end;
      const std::string da = a.substr(i, i_end - i), db = b.substr(j, j_end - j);
      const std::string ta = da.substr(std::min(da.find_first_not_of('0'), da.size()));
      const std::string tb = db.substr(std::min(db.find_first_not_of('0'), db.size()));
      if (ta.size() != tb.size()) return ta.size() < tb.size();
      if (ta != tb) return ta < tb;
      i = i_end;
      j = j_end;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

std::unique_ptr<DatasetReader> OpenImageFolder(const std::string& path,
                                               const std::string& calibration) {
  const fs::path folder(path);
  const fs::path images = fs::is_directory(folder / "images") ? folder / "images" : folder;
  const std::string calib_file = FindCalibrationFile(path, calibration);
  if (calib_file.empty()) {
    throw InputError(path,
                     "image folder needs a calibration: add calibration.yaml or pass --calib");
  }
  const CalibrationFile calib = ReadCalibrationYaml(calib_file);
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(images)) {
    if (entry.is_regular_file() && IsImageFile(entry.path()))
      files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end(), NaturalLess);
  if (files.empty()) throw InputError(images.string(), "contains no images");
  FileListSpec spec;
  spec.format = DatasetFormat::kImages;
  spec.camera = calib.camera;
  const std::string times = (folder / "times.txt").string();
  if (fs::exists(times)) {
    // One timestamp per line, or "<id or name> <timestamp> ..." (monoVO style).
    ForEachDataLine(times, [&](const std::string& line, int line_number) {
      const auto fields = SplitFields(line);
      if (spec.entries.size() >= files.size())
        throw InputError(times, line_number, "more lines than images");
      ImageEntry entry;
      entry.timestamp =
          ParseDouble(fields.size() == 1 ? fields[0] : fields[1], times, line_number, "timestamp");
      entry.path = files[spec.entries.size()];
      entry.list_file = times;
      entry.list_line = line_number;
      spec.entries.push_back(std::move(entry));
    });
    if (spec.entries.size() != files.size()) {
      throw InputError(times, "has " + std::to_string(spec.entries.size()) + " timestamps for " +
                                  std::to_string(files.size()) + " images");
    }
  } else {
    if (!calib.fps) {
      throw InputError(calib_file, "no times.txt beside the images, so 'fps' is required");
    }
    for (std::size_t i = 0; i < files.size(); ++i) {
      spec.entries.push_back(
          {static_cast<double>(i) / *calib.fps, files[i], std::nullopt, calib_file, 0});
    }
  }
  return std::make_unique<FileListReader>(std::move(spec));
}

}  // namespace parallax
