#include "tools/bench/suite.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <set>
#include <vector>

#include "tools/dataset/input_error.hpp"

namespace fs = std::filesystem;

namespace parallax::bench {
namespace {

int LineOf(const YAML::Node& node) { return node.Mark().line + 1; }

class Reader {
 public:
  Reader(std::string file, fs::path base) : file_(std::move(file)), base_(std::move(base)) {}

  [[noreturn]] void Fail(const YAML::Node& node, const std::string& message) const {
    throw InputError(file_, LineOf(node), message);
  }

  void CheckKeys(const YAML::Node& map, const std::set<std::string>& allowed) const {
    if (!map.IsMap()) Fail(map, "expected a mapping");
    for (const auto& entry : map) {
      const auto key = entry.first.as<std::string>();
      if (!allowed.count(key)) Fail(entry.first, "unknown key '" + key + "'");
    }
  }

  template <typename T>
  T Get(const YAML::Node& map, const char* key, T fallback) const {
    const YAML::Node node = map[key];
    if (!node) return fallback;
    try {
      return node.as<T>();
    } catch (const YAML::Exception&) {
      Fail(node, std::string("'") + key + "' has a value of the wrong type");
    }
  }

  /// A path relative to the suite file; `must_exist` checks it.
  std::string PathOf(const YAML::Node& map, const char* key, bool must_exist) const {
    auto text = Get<std::string>(map, key, "");
    if (text.empty()) return text;
    const fs::path p = fs::path(text).is_absolute() ? fs::path(text) : base_ / text;
    if (must_exist && !fs::exists(p)) Fail(map[key], "'" + p.string() + "' does not exist");
    return fs::weakly_canonical(p).string();
  }

  synth::SynthOptions Synth(const YAML::Node& node) const {
    CheckKeys(node, {"scene", "motion", "frames", "seed", "fps", "exposure", "noise", "vignette",
                     "blur", "width", "height", "gamma", "layout"});
    synth::SynthOptions o;
    o.scene = Get<std::string>(node, "scene", o.scene);
    o.motion = Get<std::string>(node, "motion", o.motion);
    o.frames = Get<int>(node, "frames", 90);
    o.seed = Get<std::uint64_t>(node, "seed", o.seed);
    o.fps = Get<double>(node, "fps", o.fps);
    o.exposure = Get<bool>(node, "exposure", o.exposure);
    o.noise_sigma = Get<double>(node, "noise", o.noise_sigma);
    o.vignette = Get<bool>(node, "vignette", o.vignette);
    o.blur = Get<bool>(node, "blur", o.blur);
    o.width = Get<int>(node, "width", o.width);
    o.height = Get<int>(node, "height", o.height);
    o.response_gamma = Get<double>(node, "gamma", o.response_gamma);
    o.layout = Get<std::string>(node, "layout", o.layout);
    try {
      o.Check();
    } catch (const std::invalid_argument& e) {
      Fail(node, e.what());
    }
    return o;
  }

  /// The sequence once per entry of `first_frames` (named NAME@k), or once as it is.
  std::vector<SequenceSpec> Starts(const YAML::Node& node, const SequenceSpec& s) const {
    const YAML::Node list = node["first_frames"];
    if (!list) return {s};
    if (!list.IsSequence() || list.size() == 0) {
      Fail(list, "'first_frames' must be a non-empty list of frame indices");
    }
    // A peer's trajectory covers the whole sequence, not the run from a start.
    if (!s.peers.empty()) Fail(list, "'first_frames' cannot be combined with 'peers'");
    std::vector<SequenceSpec> starts;
    for (const YAML::Node& entry : list) {
      int k = -1;
      try {
        k = entry.as<int>();
      } catch (const YAML::Exception&) {
        Fail(entry, "'first_frames' entries must be integers");
      }
      if (k < 0 || (s.max_frames > 0 && k >= s.max_frames)) {
        Fail(entry, "a first frame must be >= 0 and below max_frames");
      }
      SequenceSpec start = s;
      start.first_frame = k;
      start.name = fmt::format("{}@{}", s.name, k);
      starts.push_back(std::move(start));
    }
    return starts;
  }

  Tolerance TolerancesOf(const YAML::Node& node) const {
    Tolerance t;
    if (!node) return t;
    CheckKeys(node, {"ate_relative", "ate_absolute", "coverage"});
    t.ate_relative = Get<double>(node, "ate_relative", t.ate_relative);
    t.ate_absolute = Get<double>(node, "ate_absolute", t.ate_absolute);
    t.coverage = Get<double>(node, "coverage", t.coverage);
    if (t.ate_relative < 0 || t.ate_absolute < 0 || t.coverage < 0) {
      Fail(node, "tolerances must be >= 0");
    }
    return t;
  }

 private:
  std::string file_;
  fs::path base_;
};

/// A folder name that changes with every parameter of the rendering.
std::string CacheName(const synth::SynthOptions& o) {
  return fmt::format("{}-{}-{}f-seed{}-{}fps-{}x{}{}{}{}{}{}{}", o.scene, o.motion, o.frames,
                     o.seed, o.fps, o.width, o.height, o.exposure ? "-exposure" : "",
                     o.noise_sigma > 0 ? fmt::format("-noise{}", o.noise_sigma) : "",
                     o.vignette ? "-vignette" : "", o.blur ? "-blur" : "",
                     o.response_gamma != 1.0 ? fmt::format("-gamma{}", o.response_gamma) : "",
                     o.layout != "tum_rgbd" ? "-" + o.layout : "");
}

}  // namespace

Suite ReadSuite(const std::string& file, const std::string& cache_dir) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(file);
  } catch (const YAML::BadFile&) {
    throw InputError(file, "cannot open suite file");
  } catch (const YAML::ParserException& e) {
    throw InputError(file, e.mark.line + 1, "YAML syntax error: " + e.msg);
  }
  const Reader r(file, fs::absolute(file).parent_path());
  r.CheckKeys(root, {"name", "sequences", "configurations"});
  Suite suite;
  suite.file = fs::absolute(file).string();
  suite.name = r.Get<std::string>(root, "name", fs::path(file).stem().string());
  const YAML::Node sequences = root["sequences"];
  if (!sequences || !sequences.IsSequence() || sequences.size() == 0) {
    throw InputError(file, "needs a non-empty 'sequences' list");
  }
  std::set<std::string> names;
  for (const YAML::Node& node : sequences) {
    r.CheckKeys(node, {"name", "path", "synth", "format", "calibration", "groundtruth", "config",
                       "max_frames", "first_frames", "tolerance", "peers"});
    SequenceSpec s;
    s.name = r.Get<std::string>(node, "name", "");
    if (s.name.empty()) r.Fail(node, "a sequence needs a 'name'");
    if (node["synth"] && node["path"]) r.Fail(node, "give 'path' or 'synth', not both");
    if (node["synth"]) {
      s.synth = r.Synth(node["synth"]);
      s.path = (fs::absolute(cache_dir) / CacheName(*s.synth)).string();
    } else {
      s.path = r.PathOf(node, "path", true);
      if (s.path.empty()) r.Fail(node, "a sequence needs a 'path' or 'synth'");
    }
    s.format = r.Get<std::string>(node, "format", s.format);
    s.calibration = r.PathOf(node, "calibration", true);
    s.groundtruth = r.PathOf(node, "groundtruth", true);
    s.config = r.PathOf(node, "config", true);
    s.max_frames = r.Get<int>(node, "max_frames", 0);
    if (s.max_frames < 0) r.Fail(node["max_frames"], "max_frames must be >= 0");
    s.tolerance = r.TolerancesOf(node["tolerance"]);
    if (const YAML::Node peers = node["peers"]) {
      if (!peers.IsMap()) r.Fail(peers, "'peers' must map names to trajectory files");
      for (const auto& peer : peers) {
        YAML::Node holder;
        holder["p"] = peer.second;
        s.peers[peer.first.as<std::string>()] = r.PathOf(holder, "p", false);
      }
    }
    for (SequenceSpec& start : r.Starts(node, s)) {
      if (!names.insert(start.name).second) {
        r.Fail(node["name"], "duplicate sequence '" + start.name + "'");
      }
      suite.sequences.push_back(std::move(start));
    }
  }
  if (const YAML::Node configurations = root["configurations"]) {
    std::set<std::string> config_names;
    for (const YAML::Node& node : configurations) {
      r.CheckKeys(node, {"name", "config", "realtime_rate"});
      Configuration c;
      c.name = r.Get<std::string>(node, "name", "");
      if (c.name.empty()) r.Fail(node, "a configuration needs a 'name'");
      if (!config_names.insert(c.name).second) r.Fail(node, "duplicate configuration");
      c.config = r.PathOf(node, "config", true);
      if (node["realtime_rate"]) {
        c.realtime_rate = r.Get<double>(node, "realtime_rate", 0.0);
        if (!(*c.realtime_rate >= 0.0) || !std::isfinite(*c.realtime_rate)) {
          r.Fail(node["realtime_rate"], "'realtime_rate' must be a finite number >= 0");
        }
      }
      suite.configurations.push_back(c);
    }
  }
  if (suite.configurations.empty()) suite.configurations.push_back(Configuration{});
  return suite;
}

}  // namespace parallax::bench
