// Building blocks of the built-in rooms (lib/lightfield/scenes.cc): groin vaults, columns,
// arcades, tiled floors. Scene frame, mm, y up. Every part is built so that neighbouring parts
// meet exactly: vaults over bays that share an edge use the same vertices along it, and a
// surface that ends on another one ends on its plane (a wall rises past the vault that meets
// it), so no ray from inside a room escapes between two parts
// (tests/lib/lightfield/scenes_test.cc).
#pragma once

#include <Eigen/Core>

#include "lib/lightfield/scenes.h"

namespace lumislab {
namespace scene_parts {

using V = Eigen::Vector3f;

// Quad a-b-c-d whose normal points along `towards` (the vertex order is reversed if needed).
void AddQuadFacing(Mesh& m, const V& a, const V& b, const V& c, const V& d, const V& towards,
                   const V& colour);

// Box sides: which faces AddBoxFaces adds.
enum BoxFace : unsigned {
  kMinusX = 1,
  kPlusX = 2,
  kMinusY = 4,
  kPlusY = 8,
  kMinusZ = 16,
  kPlusZ = 32,
  kSides = kMinusX | kPlusX | kMinusZ | kPlusZ,
};
// Axis-aligned box, the faces in `faces` only (faces that lie on the floor or under a vault are
// never seen and only cost shadow-map time), all pointing out.
void AddBoxFaces(Mesh& m, const V& lo, const V& hi, unsigned faces, const V& colour);

// Groin vault over the bay [x0, x1] x [z0, z1], springing at height `spring` at its four corners,
// crown `spring + rise`: two half-elliptic barrels crossing, the ceiling at (x, z) is
// spring + rise * max(sin(a(x)), sin(a(z))) where a runs 0 .. pi across the bay (so the groins
// run along the diagonals). `segments` (even) pieces per half ellipse; each of the four webs is
// a ruled strip of planar quads; faces point down into the room. Two bays that share an edge and
// have the same spring, rise and segments share its vertices exactly.
void AddGroinVault(Mesh& m, float x0, float x1, float z0, float z1, float spring, float rise,
                   int segments, const V& colour);

struct ColumnStyle {
  float radius = 150;       // shaft
  int sides = 8;            // shaft facets
  float base_half = 220;    // square plinth, half side
  float base_height = 200;  // plinth
  float cap_half = 220;     // square abacus, half side
  float cap_height = 180;   // abacus
};
// A column standing on the floor y0 up to y1 at (x, z): square plinth, faceted shaft, square
// abacus (the plinth's bottom, on the floor, is left out).
void AddColumn(Mesh& m, float x, float z, float y0, float y1, const ColumnStyle& style,
               const V& colour, const V& trim);

// A wall of round arches along x, between z = z_front (facing -z) and z_back (facing +z):
// openings between `xs[k] + half_pier` and `xs[k+1] - half_pier`, semicircular from `spring`,
// the wall closed above them up to `top`. `segments` pieces per arch. The piers under the arches
// (columns) are not part of it; nor are the ends at xs.front() and xs.back() (they meet a pier)
// or its top (under a roof). For the other sides of a courtyard, Transform the result.
void AddArcadeWall(Mesh& m, const std::vector<float>& xs, float half_pier, float z_front,
                   float z_back, float spring, float top, int segments, const V& colour);

// Floor y = 0 over [x0, x1] x [z0, z1] (facing up) in nx x nz tiles of two alternating colours.
void AddTiledFloor(Mesh& m, float x0, float x1, float z0, float z1, int nx, int nz, const V& a,
                   const V& b);

// Rotates the mesh by `quarter_turns` x 90 degrees about the y axis (positions and normals).
void RotateQuarterTurns(Mesh& m, int quarter_turns);

}  // namespace scene_parts
}  // namespace lumislab
