#include "tools/synth/renderer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace parallax::synth {
namespace {

using Eigen::Vector3d;

// A quad in camera coordinates with what per-pixel tests need.
struct CameraQuad {
  Vector3d origin;
  Vector3d edge_u;
  Vector3d edge_v;
  Vector3d normal;      // unit
  double plane_offset;  // normal . origin
  double inv_u_sq;      // 1 / |edge_u|^2
  double inv_v_sq;
  int index;  // into scene.quads
};

struct Hit {
  double z = std::numeric_limits<double>::infinity();
  float s = 0.0f;
  float r = 0.0f;
  int quad = -1;
};

// Intersection of the ray (x, y, 1) with a quad; z = ray parameter = depth.
bool Intersect(const CameraQuad& q, double x, double y, double near_plane, Hit* hit) {
  const double denominator = q.normal.x() * x + q.normal.y() * y + q.normal.z();
  if (denominator >= -1e-12) return false;  // parallel or seen from behind
  const double z = q.plane_offset / denominator;
  if (z <= near_plane || z >= hit->z) return false;
  const Vector3d w(x * z - q.origin.x(), y * z - q.origin.y(), z - q.origin.z());
  const double s = w.dot(q.edge_u) * q.inv_u_sq;
  const double r = w.dot(q.edge_v) * q.inv_v_sq;
  if (s < 0.0 || s >= 1.0 || r < 0.0 || r >= 1.0) return false;
  *hit = {z, static_cast<float>(s), static_cast<float>(r), q.index};
  return true;
}

std::vector<CameraQuad> VisibleQuads(const Scene& scene, const SE3d& T_c_w) {
  std::vector<CameraQuad> out;
  for (std::size_t i = 0; i < scene.quads.size(); ++i) {
    const Quad& q = scene.quads[i];
    CameraQuad c;
    c.origin = T_c_w * q.origin;
    c.edge_u = T_c_w.Rotation() * q.edge_u;
    c.edge_v = T_c_w.Rotation() * q.edge_v;
    c.normal = c.edge_u.cross(c.edge_v).normalized();
    c.plane_offset = c.normal.dot(c.origin);
    if (c.plane_offset >= 0.0) continue;  // camera is behind the visible side
    c.inv_u_sq = 1.0 / c.edge_u.squaredNorm();
    c.inv_v_sq = 1.0 / c.edge_v.squaredNorm();
    c.index = static_cast<int>(i);
    out.push_back(c);
  }
  return out;
}

// Pixel bounding box of a quad; the whole image if it crosses the near plane.
std::array<int, 4> ScreenBox(const CameraQuad& q, const PinholeCamera& K, double near_plane) {
  const int w = K.Width(), h = K.Height();
  double x0 = 1e30, y0 = 1e30, x1 = -1e30, y1 = -1e30;
  for (const Vector3d& p : {q.origin, Vector3d(q.origin + q.edge_u), Vector3d(q.origin + q.edge_v),
                            Vector3d(q.origin + q.edge_u + q.edge_v)}) {
    if (p.z() <= near_plane) return {0, 0, w - 1, h - 1};
    const Eigen::Vector2d uv = K.Project(p);
    x0 = std::min(x0, uv.x());
    y0 = std::min(y0, uv.y());
    x1 = std::max(x1, uv.x());
    y1 = std::max(y1, uv.y());
  }
  const auto clamp_x = [w](double v) { return static_cast<int>(std::clamp(v, 0.0, w - 1.0)); };
  const auto clamp_y = [h](double v) { return static_cast<int>(std::clamp(v, 0.0, h - 1.0)); };
  return {clamp_x(std::floor(x0) - 1), clamp_y(std::floor(y0) - 1), clamp_x(std::ceil(x1) + 1),
          clamp_y(std::ceil(y1) + 1)};
}

float Shade(const Scene& scene, const Hit& hit, double ray_x, double ray_y, const CameraQuad& q,
            double focal) {
  const Quad& quad = scene.quads[static_cast<std::size_t>(hit.quad)];
  const double len_u = quad.edge_u.norm(), len_v = quad.edge_v.norm();
  const double u = hit.s * len_u / quad.texture_scale + quad.texture_offset.x();
  const double v = hit.r * len_v / quad.texture_scale + quad.texture_offset.y();
  // Footprint of one pixel on the surface: z / (f cos(angle)), in texels of level 0.
  const double ray_norm = std::sqrt(ray_x * ray_x + ray_y * ray_y + 1.0);
  const double cos_angle = std::max(0.05, -q.normal.dot(Vector3d(ray_x, ray_y, 1.0)) / ray_norm);
  const Texture& texture = scene.textures[static_cast<std::size_t>(quad.texture)];
  const double texels =
      hit.z * ray_norm / (focal * cos_angle) / quad.texture_scale * texture.Size();
  return quad.brightness *
         texture.Sample(static_cast<float>(u), static_cast<float>(v), static_cast<float>(texels));
}

}  // namespace

RenderedView Render(const Scene& scene, const PinholeCamera& K, const SE3d& T_w_c,
                    const RenderOptions& options) {
  const int w = K.Width(), h = K.Height();
  const std::vector<CameraQuad> quads = VisibleQuads(scene, T_w_c.Inverse());
  std::vector<int> slot_of_quad(scene.quads.size(), -1);
  for (std::size_t i = 0; i < quads.size(); ++i)
    slot_of_quad[static_cast<std::size_t>(quads[i].index)] = static_cast<int>(i);
  std::vector<Hit> hits(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  const double inv_fx = 1.0 / K.Fx(), inv_fy = 1.0 / K.Fy();
  for (const CameraQuad& q : quads) {
    const auto [bx0, by0, bx1, by1] = ScreenBox(q, K, options.near_plane);
    for (int y = by0; y <= by1; ++y) {
      const double ray_y = (y - K.Cy()) * inv_fy;
      Hit* row = hits.data() + static_cast<std::ptrdiff_t>(y) * w;
      for (int x = bx0; x <= bx1; ++x)
        Intersect(q, (x - K.Cx()) * inv_fx, ray_y, options.near_plane, &row[x]);
    }
  }
  RenderedView view{ImageF(w, h), ImageF(w, h, 0.0f)};
  const double focal = 0.5 * (K.Fx() + K.Fy());
  const auto shade_ray = [&](const Hit& hit, double rx, double ry) {
    if (hit.quad < 0) return scene.sky;
    return Shade(scene, hit, rx, ry,
                 quads[static_cast<std::size_t>(slot_of_quad[static_cast<std::size_t>(hit.quad)])],
                 focal);
  };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Hit& hit = hits[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) +
                            static_cast<std::size_t>(x)];
      const double rx = (x - K.Cx()) * inv_fx, ry = (y - K.Cy()) * inv_fy;
      bool edge = false;
      if (options.antialias) {
        for (const auto& [dx, dy] :
             {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
          const int nx = x + dx, ny = y + dy;
          edge |= nx >= 0 && ny >= 0 && nx < w && ny < h &&
                  hits[static_cast<std::size_t>(ny) * static_cast<std::size_t>(w) +
                       static_cast<std::size_t>(nx)]
                          .quad != hit.quad;
        }
      }
      if (!edge) {
        view.intensity(x, y) = shade_ray(hit, rx, ry);
      } else {
        // Geometry edge: average 4 sub-pixel rays against all visible quads.
        float sum = 0.0f;
        for (const auto& [ox, oy] : {std::pair{-0.25, -0.25}, std::pair{0.25, -0.25},
                                     std::pair{-0.25, 0.25}, std::pair{0.25, 0.25}}) {
          const double sx = (x + ox - K.Cx()) * inv_fx, sy = (y + oy - K.Cy()) * inv_fy;
          Hit sub;
          for (const CameraQuad& q : quads) Intersect(q, sx, sy, options.near_plane, &sub);
          sum += shade_ray(sub, sx, sy);
        }
        view.intensity(x, y) = 0.25f * sum;
      }
      if (hit.quad >= 0) view.depth(x, y) = static_cast<float>(hit.z);
    }
  }
  return view;
}

}  // namespace parallax::synth
