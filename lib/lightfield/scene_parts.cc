#include "lib/lightfield/scene_parts.h"

#include <Eigen/Geometry>
#include <cmath>
#include <utility>
#include <vector>

#include "core/geometry.h"

namespace lumislab {
namespace scene_parts {
namespace {

constexpr float kPiF = float(kPi);

// Half-ellipse profile over [-1, 1]: offsets c_k (exactly -1, 0, 1 at the ends and the middle)
// and heights s_k = sin(pi k / n) (exactly 0 and 1 there), mirror-symmetric to the last bit so
// that the webs of a groin vault meet on its diagonals at identical vertices.
struct Profile {
  std::vector<float> c, s;
  explicit Profile(int n) : c(n + 1), s(n + 1) {
    for (int k = 0; 2 * k <= n; ++k) {
      const float angle = kPiF * k / n;
      c[k] = 2 * k == n ? 0.0f : (k == 0 ? -1.0f : -std::cos(angle));
      s[k] = 2 * k == n ? 1.0f : (k == 0 ? 0.0f : std::sin(angle));
      c[n - k] = -c[k];
      s[n - k] = s[k];
    }
  }
};

// Point at parameter t in [-1, 1] of [lo, hi]: exactly lo and hi at the ends, so that two bays
// sharing an edge compute the same coordinates there.
float Along(float lo, float hi, float t) {
  if (t == -1.0f) return lo;
  if (t == 1.0f) return hi;
  return 0.5f * (lo + hi) + 0.5f * (hi - lo) * t;
}

// Quad a-b-c-d of a curved surface with its normals there (unit, on the side the quad faces;
// the vertex order is reversed if the quad's own normal points away from them). Both renderers
// interpolate the normals alike; the shadows follow the flat triangles.
void AddSmoothQuad(Mesh& m, V a, V b, const V& c, V d, V na, V nb, const V& nc, V nd,
                   const V& colour) {
  if (((b - a).cross(c - a) + (c - a).cross(d - a)).dot(na + nb + nc + nd) < 0) {
    std::swap(b, d);
    std::swap(nb, nd);
  }
  auto triangle = [&](const V& p, const V& q, const V& r, const V& np, const V& nq, const V& nr) {
    if ((q - p).cross(r - p).norm() == 0) return;
    for (const V* v : {&p, &q, &r}) m.positions.push_back(*v);
    for (const V* n : {&np, &nq, &nr}) m.normals.push_back(n->normalized());
    for (int k = 0; k < 3; ++k) m.albedo.push_back(colour);
  };
  triangle(a, b, c, na, nb, nc);
  triangle(a, c, d, na, nc, nd);
}

}  // namespace

void AddQuadFacing(Mesh& m, const V& a, const V& b, const V& c, const V& d, const V& towards,
                   const V& colour) {
  // The larger of the two triangles' normals decides (one of them may be degenerate).
  const V n = (b - a).cross(c - a) + (c - a).cross(d - a);
  if (n.dot(towards) >= 0) {
    m.AddQuad(a, b, c, d, colour);
  } else {
    m.AddQuad(a, d, c, b, colour);
  }
}

void AddBoxFaces(Mesh& m, const V& lo, const V& hi, unsigned faces, const V& colour) {
  const V p[8] = {{lo.x(), lo.y(), lo.z()}, {hi.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), lo.z()},
                  {lo.x(), hi.y(), lo.z()}, {lo.x(), lo.y(), hi.z()}, {hi.x(), lo.y(), hi.z()},
                  {hi.x(), hi.y(), hi.z()}, {lo.x(), hi.y(), hi.z()}};
  if (faces & kMinusZ) m.AddQuad(p[0], p[3], p[2], p[1], colour);
  if (faces & kPlusZ) m.AddQuad(p[4], p[5], p[6], p[7], colour);
  if (faces & kMinusX) m.AddQuad(p[0], p[4], p[7], p[3], colour);
  if (faces & kPlusX) m.AddQuad(p[1], p[2], p[6], p[5], colour);
  if (faces & kMinusY) m.AddQuad(p[0], p[1], p[5], p[4], colour);
  if (faces & kPlusY) m.AddQuad(p[3], p[7], p[6], p[2], colour);
}

void AddGroinVault(Mesh& m, float x0, float x1, float z0, float z1, float spring, float rise,
                   int segments, const V& colour) {
  const Profile p(segments);
  const float sx = 0.5f * (x1 - x0), sz = 0.5f * (z1 - z0);
  auto height = [&](int k) { return p.s[k] == 0 ? spring : spring + rise * p.s[k]; };
  // The barrels' normals at profile point k: (0, -s sin, rise cos) for the one whose height
  // follows z (into the bay at the springing, down at the crown), likewise along x.
  auto normal_z = [&](int k) { return V(0, -sz * p.s[k], -rise * p.c[k]).normalized(); };
  auto normal_x = [&](int k) { return V(-rise * p.c[k], -sx * p.s[k], 0).normalized(); };
  for (int k = 0; k < segments; ++k) {
    const float h0 = height(k), h1 = height(k + 1);
    const float a0 = std::abs(p.c[k]), a1 = std::abs(p.c[k + 1]);
    const V nz0 = normal_z(k), nz1 = normal_z(k + 1), nx0 = normal_x(k), nx1 = normal_x(k + 1);
    // Webs against the edges x = x1 and x = x0: height follows z; the inner edge is the groin.
    for (const float side : {1.0f, -1.0f}) {
      const float outer = side > 0 ? x1 : x0;
      const float za = Along(z0, z1, p.c[k]), zb = Along(z0, z1, p.c[k + 1]);
      AddSmoothQuad(m, {Along(x0, x1, side * a0), h0, za}, {outer, h0, za}, {outer, h1, zb},
                    {Along(x0, x1, side * a1), h1, zb}, nz0, nz0, nz1, nz1, colour);
    }
    // Webs against z = z1 and z = z0: height follows x.
    for (const float side : {1.0f, -1.0f}) {
      const float outer = side > 0 ? z1 : z0;
      const float xa = Along(x0, x1, p.c[k]), xb = Along(x0, x1, p.c[k + 1]);
      AddSmoothQuad(m, {xa, h0, Along(z0, z1, side * a0)}, {xa, h0, outer}, {xb, h1, outer},
                    {xb, h1, Along(z0, z1, side * a1)}, nx0, nx0, nx1, nx1, colour);
    }
  }
}

void AddColumn(Mesh& m, float x, float z, float y0, float y1, const ColumnStyle& style,
               const V& colour, const V& trim) {
  const float b = style.base_half, c = style.cap_half;
  const float shaft0 = y0 + style.base_height, shaft1 = y1 - style.cap_height;
  AddBoxFaces(m, {x - b, y0, z - b}, {x + b, shaft0, z + b}, kSides | kPlusY, trim);
  AddBoxFaces(m, {x - c, shaft1, z - c}, {x + c, y1, z + c}, kSides | kMinusY | kPlusY, trim);
  for (int k = 0; k < style.sides; ++k) {
    const float a0 = 2 * kPiF * k / style.sides, a1 = 2 * kPiF * (k + 1) / style.sides;
    const V p0(x + style.radius * std::cos(a0), 0, z + style.radius * std::sin(a0));
    const V p1(x + style.radius * std::cos(a1), 0, z + style.radius * std::sin(a1));
    const V n0(std::cos(a0), 0, std::sin(a0)), n1(std::cos(a1), 0, std::sin(a1));  // round
    AddSmoothQuad(m, p0 + V(0, shaft0, 0), p1 + V(0, shaft0, 0), p1 + V(0, shaft1, 0),
                  p0 + V(0, shaft1, 0), n0, n1, n1, n0, colour);
  }
}

void AddArcadeWall(Mesh& m, const std::vector<float>& xs, float half_pier, float z_front,
                   float z_back, float spring, float top, int segments, const V& colour) {
  const Profile p(segments);
  const V front(0, 0, -1), back(0, 0, 1);
  for (size_t bay = 0; bay + 1 < xs.size(); ++bay) {
    const float lo = xs[bay] + half_pier, hi = xs[bay + 1] - half_pier;
    const float radius = 0.5f * (hi - lo);
    auto point = [&](int k) {  // on the arch, in the wall's plane (x, y)
      return Eigen::Vector2f(Along(lo, hi, p.c[k]),
                             p.s[k] == 0 ? spring : spring + radius * p.s[k]);
    };
    const Eigen::Vector2f centre(0.5f * (lo + hi), spring);
    for (int k = 0; k < segments; ++k) {
      const Eigen::Vector2f q0 = point(k), q1 = point(k + 1);
      // Intrados, facing the arch's centre (round); the wall above the arch, front and back.
      const Eigen::Vector2f in0 = (centre - q0).normalized(), in1 = (centre - q1).normalized();
      const V n0(in0.x(), in0.y(), 0), n1(in1.x(), in1.y(), 0);
      AddSmoothQuad(m, {q0.x(), q0.y(), z_front}, {q1.x(), q1.y(), z_front},
                    {q1.x(), q1.y(), z_back}, {q0.x(), q0.y(), z_back}, n0, n1, n1, n0, colour);
      for (const float z : {z_front, z_back}) {
        AddQuadFacing(m, {q0.x(), q0.y(), z}, {q1.x(), q1.y(), z}, {q1.x(), top, z},
                      {q0.x(), top, z}, z == z_front ? front : back, colour);
      }
    }
    // Over the pier between this arch and the next.
    if (bay + 2 < xs.size()) {
      const float a = hi, b = xs[bay + 1] + half_pier;
      for (const float z : {z_front, z_back}) {
        AddQuadFacing(m, {a, spring, z}, {b, spring, z}, {b, top, z}, {a, top, z},
                      z == z_front ? front : back, colour);
      }
    }
  }
}

void AddTiledFloor(Mesh& m, float x0, float x1, float z0, float z1, int nx, int nz, const V& a,
                   const V& b) {
  for (int i = 0; i < nx; ++i) {
    const float xa = i == 0 ? x0 : x0 + (x1 - x0) * i / nx;
    const float xb = i + 1 == nx ? x1 : x0 + (x1 - x0) * (i + 1) / nx;
    for (int k = 0; k < nz; ++k) {
      const float za = k == 0 ? z0 : z0 + (z1 - z0) * k / nz;
      const float zb = k + 1 == nz ? z1 : z0 + (z1 - z0) * (k + 1) / nz;
      AddQuadFacing(m, {xa, 0, za}, {xb, 0, za}, {xb, 0, zb}, {xa, 0, zb}, V(0, 1, 0),
                    (i + k) % 2 ? b : a);
    }
  }
}

void RotateQuarterTurns(Mesh& m, int quarter_turns) {
  // (x, z) -> (z, -x) per turn: exact in floats (no rounding), so rotated copies of a part
  // meet their neighbours at identical vertices.
  auto turn = [&](V& v) {
    for (int k = 0; k < ((quarter_turns % 4) + 4) % 4; ++k) v = V(v.z(), v.y(), -v.x());
  };
  for (V& v : m.positions) turn(v);
  for (V& v : m.normals) turn(v);
}

}  // namespace scene_parts
}  // namespace lumislab
