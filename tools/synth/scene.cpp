#include "tools/synth/scene.hpp"

#include <stdexcept>

#include "tools/synth/random.hpp"

namespace parallax::synth {
namespace {

using Eigen::Vector3d;

constexpr int kTextureSize = 1024;

// Textures every scene uses, by index.
enum TextureIndex {
  kPlasterTex,
  kTilesTex,
  kWoodTex,
  kBricksTex,
  kPostersTex,
  kPrintTex,
  kAsphaltTex
};

void AddTextures(Scene* scene, std::uint64_t seed, const std::vector<std::string>& files) {
  const Material materials[] = {Material::kPlaster, Material::kTiles,   Material::kWood,
                                Material::kBricks,  Material::kPosters, Material::kPrint,
                                Material::kAsphalt};
  for (std::size_t i = 0; i < std::size(materials); ++i) {
    scene->textures.push_back(
        i < files.size() ? Texture::FromFile(files[i])
                         : Texture::Procedural(materials[i], kTextureSize, seed + 101 * i));
  }
}

// A thin textured panel on a wall (poster, picture, door): a flat box.
void AddPanel(Scene* scene, const Vector3d& lo, const Vector3d& hi, int texture, double scale) {
  AddBox(scene, lo, hi, texture, scale);
}

void BuildRoom(Scene* s) {
  AddBox(s, {-3.0, -1.6, -3.0}, {3.0, 1.4, 5.0}, kPlasterTex, 1.5, /*inward=*/true);
  s->quads[3].texture = kTilesTex;  // floor (+y face seen from inside)
  s->quads[3].texture_scale = 2.0;
  AddBox(s, {0.2, 0.6, 2.0}, {1.6, 0.68, 3.0}, kWoodTex, 1.2);  // table top
  AddBox(s, {0.3, 0.68, 2.1}, {0.4, 1.4, 2.2}, kWoodTex, 1.0);  // legs
  AddBox(s, {1.4, 0.68, 2.8}, {1.5, 1.4, 2.9}, kWoodTex, 1.0);
  AddBox(s, {0.5, 0.35, 2.3}, {0.9, 0.6, 2.6}, kPrintTex, 0.4);  // books on the table
  AddBox(s, {1.0, 0.45, 2.4}, {1.3, 0.6, 2.7}, kPostersTex, 0.5);
  AddBox(s, {-2.9, -0.8, 1.0}, {-2.4, 1.4, 3.5}, kPostersTex, 1.0);    // shelf at the left wall
  AddBox(s, {-1.2, 0.5, 3.6}, {0.0, 1.4, 4.6}, kBricksTex, 1.0);       // cabinet
  AddPanel(s, {-1.0, -1.0, 4.95}, {1.2, 0.2, 5.0}, kPostersTex, 1.5);  // poster on the far wall
  AddPanel(s, {2.95, -0.9, 0.5}, {3.0, 0.3, 2.5}, kPrintTex, 1.0);     // board on the right wall
  s->rig = {{0.0, 0.0, 0.0}, {0.3, 0.3, 3.0}, {0.0, 0.0, 1.0}, 0.8, {0.3, 0.2, 2.3}, 1.6, 0.12};
}

void BuildDesk(Scene* s) {
  AddBox(s, {-2.0, -1.5, -1.0}, {2.0, 1.5, 1.6}, kPlasterTex, 1.0, /*inward=*/true);
  AddBox(s, {-1.0, 0.4, 0.2}, {1.0, 0.45, 1.6}, kWoodTex, 0.8);      // desk top
  AddBox(s, {-0.45, 0.2, 0.7}, {-0.15, 0.4, 1.0}, kPrintTex, 0.25);  // book stack
  AddBox(s, {0.05, 0.28, 0.6}, {0.35, 0.4, 0.9}, kPostersTex, 0.3);  // box
  AddBox(s, {0.4, 0.1, 1.1}, {0.7, 0.4, 1.3}, kPostersTex, 0.35);
  AddBox(s, {-0.8, 0.37, 0.5}, {-0.5, 0.4, 0.75}, kPrintTex, 0.2);     // paper
  AddPanel(s, {-0.9, -0.6, 1.55}, {0.9, 0.3, 1.6}, kPostersTex, 0.8);  // pin board
  s->rig = {{0.0, -0.2, 0.0}, {0.0, 0.3, 0.9}, {0.0, 0.0, 1.0}, 0.3, {0.0, 0.3, 0.9}, 0.6, 0.06};
  s->rig.patrol_length = 0.4;
  s->rig.patrol_radius = 0.1;
}

void BuildCorridor(Scene* s) {
  AddBox(s, {-1.1, -1.3, -2.0}, {1.1, 1.3, 30.0}, kPlasterTex, 1.2, /*inward=*/true);
  s->quads[3].texture = kTilesTex;
  for (int i = 0; i < 7; ++i) {
    const double z = 2.0 + 4.0 * i;
    const double side = i % 2 ? 1.0 : -1.0;
    AddPanel(s, {side * 1.1 - 0.05, -0.9, z}, {side * 1.1 + 0.05, 1.3, z + 1.0}, kWoodTex,
             1.0);  // door
    AddPanel(s, {-side * 1.1 - 0.04, -0.6, z + 1.5}, {-side * 1.1 + 0.04, 0.2, z + 2.5},
             kPostersTex, 1.0);
  }
  AddBox(s, {0.5, 0.6, 9.0}, {1.05, 1.3, 9.6}, kBricksTex, 0.8);  // cabinet in the corridor
  s->rig = {{0.0, 0.0, 0.0}, {0.0, 0.0, 6.0}, {0.0, 0.0, 1.0}, 1.2, {0.0, 0.0, 4.0}, 0.5, 0.1};
  s->rig.patrol_length = 20.0;  // of the 32 m corridor
  s->rig.patrol_radius = 0.6;   // in its 2.2 m width
}

void BuildStreet(Scene* s) {
  AddBox(s, {-30.0, 1.5, -10.0}, {30.0, 1.6, 80.0}, kAsphaltTex, 3.0);  // road
  for (int i = 0; i < 8; ++i) {
    const double z = -5.0 + 10.0 * i;
    AddBox(s, {-16.0, -12.0, z}, {-7.0, 1.5, z + 9.5}, kBricksTex, 4.0);          // buildings left
    AddBox(s, {7.0, -14.0, z + 2.0}, {16.0, 1.5, z + 11.0}, kBricksTex, 4.0);     // right
    AddPanel(s, {-7.05, -1.0, z + 2.0}, {-7.0, 1.0, z + 5.0}, kPostersTex, 2.0);  // shop fronts
  }
  for (int i = 0; i < 5; ++i) {
    const double z = 6.0 + 13.0 * i;
    const double x = i % 2 ? 4.0 : -5.5;
    AddBox(s, {x, 0.1, z}, {x + 1.8, 1.5, z + 4.2}, kPostersTex, 2.0);  // parked cars
  }
  s->rig = {{0.0, 0.0, 0.0}, {0.0, 0.0, 20.0}, {0.0, 0.0, 1.0}, 6.0, {0.0, 0.0, 15.0}, 4.0, 0.3};
  s->rig.patrol_length = 60.0;
  s->rig.patrol_radius = 3.0;
}

}  // namespace

std::vector<std::string> SceneNames() { return {"room", "desk", "corridor", "street"}; }

void AddBox(Scene* scene, const Vector3d& lo, const Vector3d& hi, int texture, double texture_scale,
            bool inward) {
  const Vector3d d = hi - lo;
  const Vector3d ex(d.x(), 0, 0), ey(0, d.y(), 0), ez(0, 0, d.z());
  // (origin, u, v) with u x v pointing outward; order: -x, +x, -y, +y, -z, +z.
  const std::array<std::array<Vector3d, 3>, 6> faces = {{
      {lo, ez, ey},
      {Vector3d(hi.x(), lo.y(), lo.z()), ey, ez},
      {lo, ex, ez},
      {Vector3d(lo.x(), hi.y(), lo.z()), ez, ex},
      {lo, ey, ex},
      {Vector3d(lo.x(), lo.y(), hi.z()), ex, ey},
  }};
  const float brightness[6] = {0.85f, 0.9f, 1.0f, 0.8f, 0.95f, 0.88f};
  for (std::size_t i = 0; i < faces.size(); ++i) {
    Quad q;
    q.origin = faces[i][0];
    q.edge_u = inward ? faces[i][2] : faces[i][1];
    q.edge_v = inward ? faces[i][1] : faces[i][2];
    q.texture = texture;
    q.texture_scale = texture_scale;
    const double h = HashToUnit(static_cast<std::int64_t>(scene->quads.size()), 17, 99);
    q.texture_offset = {h, HashToUnit(static_cast<std::int64_t>(scene->quads.size()), 23, 7)};
    q.brightness = brightness[i];
    scene->quads.push_back(q);
  }
}

Scene MakeScene(const std::string& name, std::uint64_t seed,
                const std::vector<std::string>& texture_files) {
  Scene scene;
  scene.name = name;
  AddTextures(&scene, seed, texture_files);
  if (name == "room") {
    BuildRoom(&scene);
  } else if (name == "desk") {
    BuildDesk(&scene);
  } else if (name == "corridor") {
    BuildCorridor(&scene);
  } else if (name == "street") {
    BuildStreet(&scene);
  } else {
    throw std::invalid_argument("unknown scene '" + name +
                                "' (expected room, desk, corridor or street)");
  }
  return scene;
}

}  // namespace parallax::synth
