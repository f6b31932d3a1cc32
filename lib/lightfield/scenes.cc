#include "lib/lightfield/scenes.h"

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "core/geometry.h"
#include "lib/lightfield/scene_parts.h"

namespace lumislab {

using V = Eigen::Vector3f;

void Mesh::AddTriangle(const V& a, const V& b, const V& c, const V& colour) {
  V n = (b - a).cross(c - a);
  if (n.norm() == 0) return;
  n.normalize();
  for (const V& p : {a, b, c}) {
    positions.push_back(p);
    normals.push_back(n);
    albedo.push_back(colour);
  }
}

void Mesh::AddQuad(const V& a, const V& b, const V& c, const V& d, const V& colour) {
  AddTriangle(a, b, c, colour);
  AddTriangle(a, c, d, colour);
}

void Mesh::Append(const Mesh& other) {
  positions.insert(positions.end(), other.positions.begin(), other.positions.end());
  normals.insert(normals.end(), other.normals.begin(), other.normals.end());
  albedo.insert(albedo.end(), other.albedo.begin(), other.albedo.end());
}

// The crypt: 3 x 3 bays of 2.2 m under groin vaults (spring 1.9 m, crown 2.8 m), the inner four
// bay corners carried by columns, the outer ones springing from the walls; a flagged floor and
// an altar against the east wall. The walls are single quads that rise past the vault's crown:
// the vault's edges lie on them, so the room is closed without matching the lunettes' vertices.
Mesh MakeCrypt() {
  using namespace scene_parts;
  Mesh m;
  const V flags_a(0.42f, 0.38f, 0.33f), flags_b(0.52f, 0.47f, 0.40f);
  const V wall(0.62f, 0.57f, 0.49f), plaster(0.80f, 0.77f, 0.70f);
  const V column(0.58f, 0.42f, 0.31f), trim(0.66f, 0.60f, 0.52f), altar(0.50f, 0.44f, 0.38f);
  const float bay = 2200, half = 1.5f * bay, spring = 1900, rise = 900;
  const float xs[4] = {-half, -0.5f * bay, 0.5f * bay, half};
  AddTiledFloor(m, -half, half, -half, half, 3, 3, flags_a, flags_b);
  const float top = spring + rise + 100;  // walls rise past the crown
  AddQuadFacing(m, {-half, 0, -half}, {half, 0, -half}, {half, top, -half}, {-half, top, -half},
                V(0, 0, 1), wall);
  AddQuadFacing(m, {-half, 0, half}, {half, 0, half}, {half, top, half}, {-half, top, half},
                V(0, 0, -1), wall);
  AddQuadFacing(m, {-half, 0, -half}, {-half, 0, half}, {-half, top, half}, {-half, top, -half},
                V(1, 0, 0), wall);
  AddQuadFacing(m, {half, 0, -half}, {half, 0, half}, {half, top, half}, {half, top, -half},
                V(-1, 0, 0), wall);
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k)
      AddGroinVault(m, xs[i], xs[i + 1], xs[k], xs[k + 1], spring, rise, 6, plaster);
  }
  ColumnStyle style;
  style.radius = 170;
  style.sides = 8;
  style.base_half = 250;
  style.base_height = 220;
  style.cap_half = 270;
  style.cap_height = 200;
  for (const float x : {xs[1], xs[2]}) {
    for (const float z : {xs[1], xs[2]}) AddColumn(m, x, z, 0, spring, style, column, trim);
  }
  // Altar block against the east wall, in the middle bay.
  AddBoxFaces(m, {half - 700, 0, -800}, {half, 1000, 800}, kMinusX | kPlusY | kMinusZ | kPlusZ,
              altar);
  return m;
}

namespace {

// One side of the cloister (the north, z > 0; the others are it turned): the arcade wall of
// five round arches on four columns between corner piers, the gallery behind it under six groin
// vaults (the last one the corner bay), its tiled floor, the lean-to roof seen from the garth
// and the outer wall up to the sky.
struct CloisterPlan {
  float garth = 5000;       // inner face of the arcade at z = garth
  float thickness = 400;    // arcade wall (and the columns' abacus)
  float gallery = 3000;     // from the arcade's back to the outer wall
  float spring = 2200;      // arches and vaults
  float vault_rise = 1100;  // gallery vault: crown 3.3 m
  float arcade_top = 3600;  // top of the arcade wall, where the roof starts
  float eaves = 5000;       // the roof meets the outer wall
  float sky = 7000;         // a dark ceiling over everything: the courtyard is closed
  int bays = 5;
  float outer() const { return garth + thickness + gallery; }
};

Mesh CloisterSide(const CloisterPlan& p) {
  using namespace scene_parts;
  Mesh m;
  const V stone(0.68f, 0.62f, 0.52f), marble(0.80f, 0.78f, 0.73f), trim(0.60f, 0.56f, 0.50f);
  const V plaster(0.82f, 0.80f, 0.74f), wall(0.72f, 0.66f, 0.56f), roof(0.50f, 0.26f, 0.18f);
  const V tile_a(0.55f, 0.33f, 0.22f), tile_b(0.64f, 0.44f, 0.31f);
  const float g = p.garth, t = p.thickness, r = p.outer();
  // Column centres on the arcade's mid-line; the first and last are the corner piers' centres.
  const float pitch = (2 * g + t) / p.bays;
  std::vector<float> xs;
  for (int k = 0; k <= p.bays; ++k)
    xs.push_back(k == p.bays ? g + 0.5f * t : -(g + 0.5f * t) + k * pitch);
  AddArcadeWall(m, xs, 0.5f * t, g, g + t, p.spring, p.arcade_top, 24, stone);
  ColumnStyle style;
  style.radius = 120;
  style.sides = 24;
  style.base_half = 190;
  style.base_height = 250;
  style.cap_half = 0.5f * t;
  style.cap_height = 220;
  for (int k = 1; k < p.bays; ++k)
    AddColumn(m, xs[k], g + 0.5f * t, 0, p.spring, style, marble, trim);
  AddBoxFaces(m, {g, 0, g}, {g + t, p.arcade_top, g + t}, kSides, stone);  // north-east pier
  // Gallery vaults: bays between the columns, the end ones out to the crossing galleries' arcade
  // faces, then the corner bay.
  std::vector<float> bays = xs;
  bays.front() = -(g + t);
  bays.back() = g + t;
  bays.push_back(r);
  for (size_t k = 0; k + 1 < bays.size(); ++k) {
    AddGroinVault(m, bays[k], bays[k + 1], g + t, r, p.spring, p.vault_rise, 18, plaster);
  }
  // Floor: this side's strip of the pinwheel around the garth (x from -g to r).
  AddTiledFloor(m, -g, r, g, r, 13, 3, tile_a, tile_b);
  // Roof from the arcade's top edge to the eaves on the outer wall (seen from the garth), and
  // the outer wall from the floor to the sky.
  AddQuadFacing(m, {-g, p.arcade_top, g}, {g, p.arcade_top, g}, {r, p.eaves, r}, {-r, p.eaves, r},
                V(0, 1, -1), roof);
  AddQuadFacing(m, {-r, 0, r}, {r, 0, r}, {r, p.sky, r}, {-r, p.sky, r}, V(0, 0, -1), wall);
  return m;
}

// A round basin (`sides` facets) at (x, z): outer wall, rim, inner wall and the water.
void AddWell(Mesh& m, float x, float z, float radius, float rim, float height, float water,
             int sides, const V& stone, const V& dark) {
  using scene_parts::AddQuadFacing;
  const float inner = radius - rim;
  for (int k = 0; k < sides; ++k) {
    const float a0 = 2 * float(kPi) * k / sides, a1 = 2 * float(kPi) * (k + 1) / sides;
    const V u0(std::cos(a0), 0, std::sin(a0)), u1(std::cos(a1), 0, std::sin(a1));
    const V c(x, 0, z), out = 0.5f * (u0 + u1);
    const V o0 = c + radius * u0, o1 = c + radius * u1, i0 = c + inner * u0, i1 = c + inner * u1;
    const V up(0, height, 0), wet(0, water, 0);
    AddQuadFacing(m, o0, o1, o1 + up, o0 + up, out, stone);
    AddQuadFacing(m, o0 + up, o1 + up, i1 + up, i0 + up, V(0, 1, 0), stone);
    AddQuadFacing(m, i0 + wet, i1 + wet, i1 + up, i0 + up, -out, stone);
    m.AddTriangle(c + wet, i1 + wet, i0 + wet, dark);
  }
}

}  // namespace

// The cloister: a 10 m garth (lawn, gravel cross paths, a well) inside four arcades of five
// round arches on columns, galleries 3 m wide under groin vaults, lean-to roofs and outer walls;
// a dark flat sky at 7 m closes the courtyard, so every ray from inside meets a surface.
Mesh MakeCloister() {
  using namespace scene_parts;
  const CloisterPlan p;
  Mesh m;
  for (int turn = 0; turn < 4; ++turn) {
    Mesh side = CloisterSide(p);
    RotateQuarterTurns(side, turn);
    m.Append(side);
  }
  const V grass(0.16f, 0.30f, 0.10f), gravel(0.58f, 0.55f, 0.48f);
  const V stone(0.62f, 0.60f, 0.56f), water(0.04f, 0.06f, 0.08f), sky(0.08f, 0.11f, 0.20f);
  // Garth: lawn quarters between two gravel paths 1.6 m wide crossing at the well.
  const float g = p.garth, w = 800;
  const float cuts[4] = {-g, -w, w, g};
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) {
      AddQuadFacing(m, {cuts[i], 0, cuts[k]}, {cuts[i + 1], 0, cuts[k]},
                    {cuts[i + 1], 0, cuts[k + 1]}, {cuts[i], 0, cuts[k + 1]}, V(0, 1, 0),
                    (i == 1 || k == 1) ? gravel : grass);
    }
  }
  AddWell(m, 0, 0, 700, 150, 650, 350, 32, stone, water);
  const float r = p.outer();
  AddQuadFacing(m, {-r, p.sky, -r}, {r, p.sky, -r}, {r, p.sky, r}, {-r, p.sky, r}, V(0, -1, 0),
                sky);
  return m;
}

Mesh MakeReceiverPlane(double plane_z_mm, double extent_mm) {
  Mesh m;
  const float h = float(0.5 * extent_mm), z = float(plane_z_mm);
  // Normal -z (towards the luminaire): counter-clockwise seen from -z.
  m.AddQuad({-h, -h, z}, {-h, h, z}, {h, h, z}, {h, -h, z}, V(1, 1, 1));
  return m;
}

}  // namespace lumislab
