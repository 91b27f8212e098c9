// Mesh fixtures written by tests: OBJ files and split-vertex variants of a mesh (triangle soups,
// flipped faces, position seams) that render exactly like the original.
#ifndef SFT_TESTS_TESTING_MESHES_H_
#define SFT_TESTS_TESTING_MESHES_H_

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

namespace sft {
namespace testing {

struct Triangles {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;

  // Appends `other` (its indices shifted); returns the index of its first vertex.
  int Append(const Triangles& other);
};

// Positions and faces of a mesh file read by ReadMesh (data/meshes/`file`).
Triangles ReadTestMesh(const std::string& file);

// Writes an OBJ with `v` lines (17 significant digits: exact round trip) and `f` lines.
void WriteObj(const std::string& path, const Triangles& mesh);

// Every face with its own three vertices (vertex 3f + k is corner k of face f).
Triangles Soup(const Triangles& mesh);
// Faces f with `flip(f)` get the reversed winding (corners 0, 2, 1); vertices stay shared.
Triangles FlipFaces(const Triangles& mesh, const std::function<bool(int)>& flip);
// The faces with `side(f)` get their own copies of every vertex they share with the other faces
// (a position seam along the border between the two sets); positions are copied exactly.
Triangles SplitAlong(const Triangles& mesh, const std::function<bool(int)>& side);
// For a mesh whose vertices are copies of the vertices of `welded` (equal coordinates), the
// index in `welded` of each vertex (−1 where none is equal).
std::vector<int> CopiesOf(const Triangles& mesh, const Triangles& welded);

}  // namespace testing
}  // namespace sft

#endif  // SFT_TESTS_TESTING_MESHES_H_
