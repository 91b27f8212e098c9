#include "tests/testing/meshes.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <tuple>

#include "src/geometry/mesh.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace testing {

int Triangles::Append(const Triangles& other) {
  const int base = static_cast<int>(positions.size());
  positions.insert(positions.end(), other.positions.begin(), other.positions.end());
  for (const Eigen::Vector3i& f : other.faces) faces.push_back(f + Eigen::Vector3i::Constant(base));
  return base;
}

Triangles ReadTestMesh(const std::string& file) {
  TriMesh mesh;
  EXPECT_TRUE(ReadMesh(DataDir() + "/meshes/" + file, &mesh).ok()) << file;
  Triangles t;
  MeshToArrays(mesh, &t.positions, &t.faces);
  return t;
}

void WriteObj(const std::string& path, const Triangles& mesh) {
  std::string text;
  char line[128];
  for (const Eigen::Vector3d& p : mesh.positions) {
    std::snprintf(line, sizeof(line), "v %.17g %.17g %.17g\n", p.x(), p.y(), p.z());
    text += line;
  }
  for (const Eigen::Vector3i& f : mesh.faces) {
    std::snprintf(line, sizeof(line), "f %d %d %d\n", f[0] + 1, f[1] + 1, f[2] + 1);
    text += line;
  }
  WriteTestFile(path, text);
}

Triangles Soup(const Triangles& mesh) {
  Triangles soup;
  for (const Eigen::Vector3i& f : mesh.faces) {
    const int base = static_cast<int>(soup.positions.size());
    for (int k = 0; k < 3; ++k) soup.positions.push_back(mesh.positions[f[k]]);
    soup.faces.emplace_back(base, base + 1, base + 2);
  }
  return soup;
}

Triangles FlipFaces(const Triangles& mesh, const std::function<bool(int)>& flip) {
  Triangles out = mesh;
  for (size_t f = 0; f < out.faces.size(); ++f) {
    if (flip(static_cast<int>(f))) std::swap(out.faces[f][1], out.faces[f][2]);
  }
  return out;
}

Triangles SplitAlong(const Triangles& mesh, const std::function<bool(int)>& side) {
  std::vector<char> used_outside(mesh.positions.size(), 0);
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    if (side(static_cast<int>(f))) continue;
    for (int k = 0; k < 3; ++k) used_outside[mesh.faces[f][k]] = 1;
  }
  Triangles out = mesh;
  std::vector<int> copy(mesh.positions.size(), -1);
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    if (!side(static_cast<int>(f))) continue;
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.faces[f][k];
      if (!used_outside[v]) continue;
      if (copy[v] < 0) {
        copy[v] = static_cast<int>(out.positions.size());
        out.positions.push_back(mesh.positions[v]);
      }
      out.faces[f][k] = copy[v];
    }
  }
  return out;
}

std::vector<int> CopiesOf(const Triangles& mesh, const Triangles& welded) {
  std::map<std::tuple<double, double, double>, int> index;
  for (size_t v = 0; v < welded.positions.size(); ++v) {
    const Eigen::Vector3d& p = welded.positions[v];
    index.emplace(std::make_tuple(p.x(), p.y(), p.z()), static_cast<int>(v));
  }
  std::vector<int> copies(mesh.positions.size(), -1);
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const Eigen::Vector3d& p = mesh.positions[v];
    const auto it = index.find(std::make_tuple(p.x(), p.y(), p.z()));
    if (it != index.end()) copies[v] = it->second;
  }
  return copies;
}

}  // namespace testing
}  // namespace sft
