#include "backend/map_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "core/binary_file.hpp"
#include "core/byte_io.hpp"
#include "core/crc32.hpp"

namespace parallax {
namespace {

constexpr char kMagic[8] = {'P', 'X', 'M', 'A', 'P', '\r', '\n', '\x1a'};
constexpr std::uint32_t kFormatVersion = 1;
/// Largest image side a map keyframe may have (a corrupt size must not allocate gigabytes
/// before the size check against the remaining bytes).
constexpr std::int32_t kMaxImageSide = 1 << 15;

using Reader = ByteReader<MapFileError>;

void PutSim3(ByteWriter* w, const Sim3d& S) {
  const Eigen::Quaterniond& q = S.Rotation().UnitQuaternion();
  for (const double v : {q.x(), q.y(), q.z(), q.w()}) w->Put(v);
  for (int k = 0; k < 3; ++k) w->Put(S.Translation()[k]);
  w->Put(S.Scale());
}

Sim3d GetSim3(Reader* r, const char* what) {
  double v[8];
  for (double& x : v) x = r->Get<double>(what);
  for (const double x : v) {
    if (!std::isfinite(x)) r->Fail(std::string(what) + " is not finite");
  }
  const Eigen::Quaterniond q(v[3], v[0], v[1], v[2]);
  if (std::abs(q.norm() - 1.0) > 1e-6) r->Fail(std::string(what) + ": rotation is not unit");
  if (v[7] <= 0.0) r->Fail(std::string(what) + ": scale is not positive");
  return Sim3d(v[7], SO3d::FromUnitQuaternion(q), Eigen::Vector3d(v[4], v[5], v[6]));
}

template <typename T>
void PutArray(ByteWriter* w, const std::vector<T>& values) {
  w->PutBytes(
      std::span(reinterpret_cast<const std::uint8_t*>(values.data()), values.size() * sizeof(T)));
}

/// `n` values; the count is checked against the bytes left before anything is allocated.
template <typename T>
std::vector<T> GetArray(Reader* r, std::size_t n, const char* what) {
  if (n > r->Remaining() / sizeof(T)) {
    r->Fail(std::string(what) + ": count " + std::to_string(n) + " exceeds the file");
  }
  std::vector<T> values(n);
  r->GetBytes(values.data(), n * sizeof(T), what);
  return values;
}

void PutKeyframe(ByteWriter* w, const KeyframeGraph& graph, const Keyframe& kf,
                 const OrbFeatures& features) {
  w->Put(kf.id);
  w->Put(kf.timestamp);
  w->Put(static_cast<std::int32_t>(graph.MapOf(kf.id)));
  w->Put(static_cast<std::uint8_t>(graph.Poses().IsFixed(kf.id) ? 1 : 0));
  PutSim3(w, graph.Pose(kf.id));
  w->Put(static_cast<std::int32_t>(kf.image.Width()));
  w->Put(static_cast<std::int32_t>(kf.image.Height()));
  w->PutBytes(std::span(kf.image.Data(), kf.image.NumPixels()));
  w->Put(static_cast<std::uint32_t>(kf.depth.Size()));
  PutArray(w, kf.depth.pixel);
  PutArray(w, kf.depth.idepth);
  PutArray(w, kf.depth.variance);
  PutArray(w, kf.depth.confirmed);
  w->Put(static_cast<std::uint32_t>(features.Size()));
  PutArray(w, features.pixel);
  PutArray(w, features.octave);
  PutArray(w, features.angle_deg);
  PutArray(w, features.descriptors);
}

void PutEdge(ByteWriter* w, const PoseGraphEdge& e) {
  w->Put(e.i);
  w->Put(e.j);
  PutSim3(w, e.S_i_j);
  for (int k = 0; k < 49; ++k) w->Put(e.information.data()[k]);
  w->Put(static_cast<std::uint8_t>(e.kind));
  w->Put(static_cast<std::uint8_t>(e.robust ? 1 : 0));
}

FrozenDepth GetDepth(Reader* r, int width, int height) {
  FrozenDepth d;
  d.width = width;
  d.height = height;
  const auto n = r->Get<std::uint32_t>("depth count");
  d.pixel = GetArray<std::int32_t>(r, n, "depth pixels");
  d.idepth = GetArray<float>(r, n, "inverse depths");
  d.variance = GetArray<float>(r, n, "depth variances");
  d.confirmed = GetArray<std::uint8_t>(r, n, "depth confirmations");
  const std::int64_t pixels = static_cast<std::int64_t>(width) * height;
  for (std::size_t k = 0; k < d.Size(); ++k) {
    if (d.pixel[k] < 0 || d.pixel[k] >= pixels || (k > 0 && d.pixel[k] <= d.pixel[k - 1])) {
      r->Fail("depth pixel " + std::to_string(k) + " is out of order or outside the image");
    }
    if (!std::isfinite(d.idepth[k]) || d.idepth[k] <= 0.0f || !std::isfinite(d.variance[k]) ||
        d.variance[k] <= 0.0f || d.confirmed[k] > 1) {
      r->Fail("depth estimate " + std::to_string(k) + " is invalid");
    }
  }
  return d;
}

OrbFeatures GetFeatures(Reader* r, int width, int height) {
  OrbFeatures f;
  const auto n = r->Get<std::uint32_t>("feature count");
  f.pixel = GetArray<Eigen::Vector2f>(r, n, "feature pixels");
  f.octave = GetArray<std::uint8_t>(r, n, "feature octaves");
  f.angle_deg = GetArray<float>(r, n, "feature angles");
  f.descriptors = GetArray<OrbDescriptor>(r, n, "feature descriptors");
  for (std::size_t k = 0; k < f.Size(); ++k) {
    const Eigen::Vector2f& p = f.pixel[k];
    if (!p.allFinite() || p.x() < -0.5f || p.y() < -0.5f || p.x() > static_cast<float>(width) ||
        p.y() > static_cast<float>(height) || !std::isfinite(f.angle_deg[k]) || f.octave[k] > 31) {
      r->Fail("feature " + std::to_string(k) + " is invalid");
    }
  }
  return f;
}

/// One keyframe record into `contents` (graph, gauge, features).
void GetKeyframe(Reader* r, MapContents* contents, std::vector<std::int64_t>* fixed) {
  auto kf = std::make_shared<Keyframe>();
  kf->id = r->Get<std::int64_t>("keyframe id");
  if (kf->id < 0 || kf->id >= contents->next_frame_id) r->Fail("keyframe id out of range");
  if (contents->graph.Size() > 0 && kf->id <= contents->graph.Ids().back()) {
    r->Fail("keyframe ids are not ascending");
  }
  kf->timestamp = r->Get<double>("keyframe timestamp");
  if (!std::isfinite(kf->timestamp)) r->Fail("keyframe timestamp is not finite");
  const auto map_id = r->Get<std::int32_t>("map id");
  if (map_id < 0 || map_id >= contents->next_map_id) r->Fail("map id out of range");
  const auto is_fixed = r->Get<std::uint8_t>("gauge flag");
  const Sim3d S_w_kf = GetSim3(r, "keyframe pose");
  const auto width = r->Get<std::int32_t>("image width");
  const auto height = r->Get<std::int32_t>("image height");
  if (width != contents->camera.Width() || height != contents->camera.Height()) {
    r->Fail("keyframe image size differs from the camera's");
  }
  if (static_cast<std::size_t>(width) * static_cast<std::size_t>(height) > r->Remaining()) {
    r->Fail("keyframe image exceeds the file");
  }
  kf->image = ImageU8(width, height);
  r->GetBytes(kf->image.Data(), kf->image.NumPixels(), "keyframe image");
  kf->depth = GetDepth(r, width, height);
  contents->features[kf->id] = GetFeatures(r, width, height);
  if (is_fixed > 1) r->Fail("gauge flag is not 0 or 1");
  if (is_fixed == 1) fixed->push_back(kf->id);
  contents->graph.Upsert(std::move(kf), S_w_kf, map_id);
}

PoseGraphEdge GetEdge(Reader* r, const KeyframeGraph& graph) {
  PoseGraphEdge e;
  e.i = r->Get<std::int64_t>("edge vertex i");
  e.j = r->Get<std::int64_t>("edge vertex j");
  if (!graph.Contains(e.i) || !graph.Contains(e.j) || e.i == e.j) {
    r->Fail("edge joins unknown keyframes");
  }
  e.S_i_j = GetSim3(r, "edge measurement");
  for (int k = 0; k < 49; ++k) e.information.data()[k] = r->Get<double>("edge information");
  if (!e.information.allFinite()) r->Fail("edge information is not finite");
  const auto kind = r->Get<std::uint8_t>("edge kind");
  if (kind > static_cast<std::uint8_t>(EdgeKind::kLoop)) r->Fail("unknown edge kind");
  e.kind = static_cast<EdgeKind>(kind);
  const auto robust = r->Get<std::uint8_t>("edge robust flag");
  if (robust > 1) r->Fail("edge robust flag is not 0 or 1");
  e.robust = robust == 1;
  return e;
}

PinholeCamera GetCamera(Reader* r) {
  const auto width = r->Get<std::int32_t>("camera width");
  const auto height = r->Get<std::int32_t>("camera height");
  double k[4];
  for (double& v : k) v = r->Get<double>("camera intrinsics");
  if (width < 1 || height < 1 || width > kMaxImageSide || height > kMaxImageSide) {
    r->Fail("camera size out of range");
  }
  for (const double v : k) {
    if (!std::isfinite(v)) r->Fail("camera intrinsics are not finite");
  }
  if (k[0] <= 0.0 || k[1] <= 0.0) r->Fail("camera focal length is not positive");
  return PinholeCamera(width, height, k[0], k[1], k[2], k[3]);
}

}  // namespace

std::vector<std::uint8_t> EncodeMap(const PinholeCamera& camera, const KeyframeGraph& graph,
                                    const std::map<std::int64_t, const OrbFeatures*>& features,
                                    std::int64_t next_frame_id, int next_map_id) {
  ByteWriter w;
  w.PutBytes(std::span(reinterpret_cast<const std::uint8_t*>(kMagic), sizeof(kMagic)));
  w.Put(kFormatVersion);
  w.Put(static_cast<std::int32_t>(camera.Width()));
  w.Put(static_cast<std::int32_t>(camera.Height()));
  for (const double v : {camera.Fx(), camera.Fy(), camera.Cx(), camera.Cy()}) w.Put(v);
  w.Put(next_frame_id);
  w.Put(static_cast<std::int32_t>(next_map_id));
  const std::vector<std::int64_t> ids = graph.Ids();
  w.Put(static_cast<std::uint32_t>(ids.size()));
  for (const std::int64_t id : ids) PutKeyframe(&w, graph, graph.Get(id), *features.at(id));
  const std::vector<PoseGraphEdge>& edges = graph.Poses().Edges();
  w.Put(static_cast<std::uint32_t>(edges.size()));
  for (const PoseGraphEdge& e : edges) PutEdge(&w, e);
  w.Put(Crc32(w.Bytes()));
  return w.Take();
}

MapContents DecodeMap(std::span<const std::uint8_t> bytes, const std::string& source) {
  Reader r(bytes, source);
  r.ReadHeader(kMagic, "map file", kFormatVersion);
  MapContents contents;
  contents.camera = GetCamera(&r);
  contents.next_frame_id = r.Get<std::int64_t>("next frame id");
  contents.next_map_id = r.Get<std::int32_t>("next map id");
  if (contents.next_frame_id < 1 || contents.next_map_id < 1) r.Fail("counters out of range");
  const auto keyframes = r.Get<std::uint32_t>("keyframe count");
  if (keyframes == 0) r.Fail("the map has no keyframe");
  std::vector<std::int64_t> fixed;
  for (std::uint32_t k = 0; k < keyframes; ++k) GetKeyframe(&r, &contents, &fixed);
  // Gauges as saved (a merged map's first keyframe is not its gauge any more).
  for (const std::int64_t id : contents.graph.Ids()) {
    const bool gauge = std::find(fixed.begin(), fixed.end(), id) != fixed.end();
    contents.graph.Poses().SetFixed(id, gauge);
  }
  const auto edges = r.Get<std::uint32_t>("edge count");
  for (std::uint32_t k = 0; k < edges; ++k) {
    const PoseGraphEdge edge = GetEdge(&r, contents.graph);
    try {  // the graph's own checks (symmetric, positive semi-definite) judge the information
      contents.graph.AddEdge(edge);
    } catch (const std::invalid_argument& e) {
      r.Fail(e.what());
    }
  }
  r.Get<std::uint32_t>("checksum");
  if (r.Remaining() != 0) r.Fail("unexpected bytes after the checksum");
  return contents;
}

void WriteMapFile(const std::string& path, std::span<const std::uint8_t> bytes) {
  try {
    WriteBinaryFileAtomically(path, bytes);
  } catch (const std::runtime_error& e) {
    throw MapFileError(e.what());
  }
}

MapContents ReadMapFile(const std::string& path) {
  std::vector<std::uint8_t> bytes;
  try {
    bytes = ReadBinaryFile(path);
  } catch (const std::runtime_error& e) {
    throw MapFileError(e.what());
  }
  return DecodeMap(bytes, path);
}

}  // namespace parallax
