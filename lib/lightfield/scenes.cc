#include "lib/lightfield/scenes.h"

#include <Eigen/Geometry>
#include <cmath>

namespace lumislab {
namespace {

using V = Eigen::Vector3f;
constexpr float kPi = 3.14159265358979f;

// A pillar of `sides` facets (radius r) from y0 to y1 at (x, z), with a square base and capital.
void AddPillar(Mesh& m, float x, float z, float r, float y0, float y1, int sides, const V& colour) {
  const float cap = 0.12f * (y1 - y0);
  m.AddBox({x - 1.4f * r, y0, z - 1.4f * r}, {x + 1.4f * r, y0 + cap, z + 1.4f * r}, colour);
  m.AddBox({x - 1.4f * r, y1 - cap, z - 1.4f * r}, {x + 1.4f * r, y1, z + 1.4f * r}, colour);
  for (int k = 0; k < sides; ++k) {
    const float a0 = 2 * kPi * k / sides;
    const float a1 = 2 * kPi * (k + 1) / sides;
    const V p0(x + r * std::cos(a0), 0, z + r * std::sin(a0));
    const V p1(x + r * std::cos(a1), 0, z + r * std::sin(a1));
    const V lo0 = p0 + V(0, y0 + cap, 0), lo1 = p1 + V(0, y0 + cap, 0);
    const V hi0 = p0 + V(0, y1 - cap, 0), hi1 = p1 + V(0, y1 - cap, 0);
    m.AddQuad(lo1, lo0, hi0, hi1, colour);
  }
}

// An arch between pillar tops a and b (at height y), `thickness` across, `segments` pieces of a
// half ellipse (rise 0.3 span), the spandrels filled up to a band 0.1 span above the crown, closed
// on top and at both ends: a solid whose faces all point out.
void AddArch(Mesh& m, const V& a, const V& b, float y, float thickness, int segments,
             const V& colour) {
  const V axis = (b - a);
  const float span = axis.norm();
  const V dir = axis / span;
  // dir x up: with the quads below, the intrados faces down and each spandrel away from the arch.
  const V side = dir.cross(V(0, 1, 0)).normalized() * (0.5f * thickness);
  const float half = 0.5f * span;
  const float rise = 0.3f * span;  // elliptical arch, flatter than a half circle
  const float top = y + rise + 0.1f * span;
  const V centre = 0.5f * (a + b) + V(0, y, 0);
  for (int k = 0; k < segments; ++k) {
    const float t0 = kPi * k / segments;
    const float t1 = kPi * (k + 1) / segments;
    const V q0 = centre - dir * (half * std::cos(t0)) + V(0, rise * std::sin(t0), 0);
    const V q1 = centre - dir * (half * std::cos(t1)) + V(0, rise * std::sin(t1), 0);
    // Intrados (underside of the arch), facing down/in.
    m.AddQuad(q0 - side, q1 - side, q1 + side, q0 + side, colour);
    // Spandrel faces on both sides: from the curve up to the top band.
    const V u0(q0.x(), top, q0.z()), u1(q1.x(), top, q1.z());
    m.AddQuad(q0 + side, q1 + side, u1 + side, u0 + side, colour);
    m.AddQuad(q1 - side, q0 - side, u0 - side, u1 - side, colour);
  }
  // Top band (extrados) facing up, and the two ends (they show at a pillar's outer corner).
  const V e0 = centre - dir * half, e1 = centre + dir * half;
  const V top0(e0.x(), top, e0.z()), top1(e1.x(), top, e1.z());
  m.AddQuad(top0 + side, top1 + side, top1 - side, top0 - side, colour);
  m.AddQuad(e0 - side, e0 + side, top0 + side, top0 - side, colour);
  m.AddQuad(e1 + side, e1 - side, top1 - side, top1 + side, colour);
}

void AddRoom(Mesh& m, const V& lo, const V& hi, const V& floor, const V& wall, const V& ceiling) {
  // Floor and ceiling (facing in), four walls facing in, each split in 4x4 quads.
  const int n = 4;
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) {
      const float x0 = lo.x() + (hi.x() - lo.x()) * a / n,
                  x1 = lo.x() + (hi.x() - lo.x()) * (a + 1) / n;
      const float z0 = lo.z() + (hi.z() - lo.z()) * b / n,
                  z1 = lo.z() + (hi.z() - lo.z()) * (b + 1) / n;
      const float y0 = lo.y() + (hi.y() - lo.y()) * b / n,
                  y1 = lo.y() + (hi.y() - lo.y()) * (b + 1) / n;
      m.AddQuad({x0, lo.y(), z1}, {x1, lo.y(), z1}, {x1, lo.y(), z0}, {x0, lo.y(), z0}, floor);
      m.AddQuad({x0, hi.y(), z0}, {x1, hi.y(), z0}, {x1, hi.y(), z1}, {x0, hi.y(), z1}, ceiling);
      m.AddQuad({x0, y0, lo.z()}, {x1, y0, lo.z()}, {x1, y1, lo.z()}, {x0, y1, lo.z()}, wall);
      m.AddQuad({x1, y0, hi.z()}, {x0, y0, hi.z()}, {x0, y1, hi.z()}, {x1, y1, hi.z()}, wall);
      const float w0 = lo.z() + (hi.z() - lo.z()) * a / n,
                  w1 = lo.z() + (hi.z() - lo.z()) * (a + 1) / n;
      m.AddQuad({lo.x(), y0, w1}, {lo.x(), y0, w0}, {lo.x(), y1, w0}, {lo.x(), y1, w1}, wall);
      m.AddQuad({hi.x(), y0, w0}, {hi.x(), y0, w1}, {hi.x(), y1, w1}, {hi.x(), y1, w0}, wall);
    }
  }
}

}  // namespace

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

void Mesh::AddBox(const V& lo, const V& hi, const V& colour) {
  const V p[8] = {{lo.x(), lo.y(), lo.z()}, {hi.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), lo.z()},
                  {lo.x(), hi.y(), lo.z()}, {lo.x(), lo.y(), hi.z()}, {hi.x(), lo.y(), hi.z()},
                  {hi.x(), hi.y(), hi.z()}, {lo.x(), hi.y(), hi.z()}};
  AddQuad(p[0], p[3], p[2], p[1], colour);  // -z
  AddQuad(p[4], p[5], p[6], p[7], colour);  // +z
  AddQuad(p[0], p[4], p[7], p[3], colour);  // -x
  AddQuad(p[1], p[2], p[6], p[5], colour);  // +x
  AddQuad(p[0], p[1], p[5], p[4], colour);  // -y
  AddQuad(p[3], p[7], p[6], p[2], colour);  // +y
}

void Mesh::Append(const Mesh& other) {
  positions.insert(positions.end(), other.positions.begin(), other.positions.end());
  normals.insert(normals.end(), other.normals.begin(), other.normals.end());
  albedo.insert(albedo.end(), other.albedo.begin(), other.albedo.end());
}

Mesh MakeCrypt() {
  // 6 m x 3 m high x 6 m room, 2x2 pillars joined by 4 arches, a low altar box.
  Mesh m;
  const V stone(0.6f, 0.55f, 0.5f), floor(0.45f, 0.42f, 0.4f), light(0.75f, 0.72f, 0.68f);
  AddRoom(m, {-3000, 0, -3000}, {3000, 3000, 3000}, floor, light, stone);
  const float p = 1200, height = 1600;
  for (float x : {-p, p}) {
    for (float z : {-p, p}) AddPillar(m, x, z, 150, 0, height, 8, stone);
  }
  AddArch(m, {-p, 0, -p}, {p, 0, -p}, height, 300, 6, light);
  AddArch(m, {-p, 0, p}, {p, 0, p}, height, 300, 6, light);
  AddArch(m, {-p, 0, -p}, {-p, 0, p}, height, 300, 6, light);
  AddArch(m, {p, 0, -p}, {p, 0, p}, height, 300, 6, light);
  m.AddBox({-400, 0, -250}, {400, 700, 250}, V(0.7f, 0.6f, 0.45f));
  return m;
}

Mesh MakeCloister() {
  // 16 m square courtyard walk: 7x7 ring of pillars with arches between neighbours, a room.
  Mesh m;
  const V stone(0.62f, 0.58f, 0.52f), floor(0.4f, 0.42f, 0.38f), light(0.78f, 0.75f, 0.7f);
  AddRoom(m, {-8000, 0, -8000}, {8000, 4000, 8000}, floor, light, stone);
  const int n = 7;
  const float spacing = 1800, height = 2000, start = -0.5f * spacing * (n - 1);
  std::vector<V> ring;
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) {
      if (a != 0 && a != n - 1 && b != 0 && b != n - 1 && a != n / 2 && b != n / 2) continue;
      const float x = start + a * spacing, z = start + b * spacing;
      AddPillar(m, x, z, 140, 0, height, 24, stone);
      if (a + 1 < n && (b == 0 || b == n - 1 || b == n / 2)) {
        AddArch(m, {x, 0, z}, {x + spacing, 0, z}, height, 280, 24, light);
      }
      if (b + 1 < n && (a == 0 || a == n - 1 || a == n / 2)) {
        AddArch(m, {x, 0, z}, {x, 0, z + spacing}, height, 280, 24, light);
      }
    }
  }
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
