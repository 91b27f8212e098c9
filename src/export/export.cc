#include "src/export/export.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "src/atlas/bake.h"
#include "src/atlas/texture_size.h"
#include "src/core/file_util.h"
#include "src/export/export_formats.h"
#include "src/geometry/material.h"
#include "src/geometry/uv_texel_charts.h"
#include "src/optim/run_outputs.h"

namespace sft {
namespace {

using json = nlohmann::json;

// The dataset to take the frame and cameras from; *found false (with a warning) when there is
// none to read. An explicit --dataset that cannot be read is an error.
Status FindDataset(const ExportOptions& options, Dataset* dataset, bool* found, json* warnings) {
  *found = false;
  if (!options.dataset.empty()) {
    SFT_RETURN_IF_ERROR(ReadDataset(options.dataset, dataset));
    *found = true;
    return Status::Ok();
  }
  const std::string state_path = JoinPath(options.reconstruction, "state.json");
  if (!FileExists(state_path)) {
    warnings->push_back(state_path + " not found: no dataset, so sft's world frame is used");
    return Status::Ok();
  }
  RunState state;
  const Status read = ReadRunState(options.reconstruction, &state);
  if (!read.ok()) {
    warnings->push_back(read.message() + " (sft's world frame is used)");
    return Status::Ok();
  }
  const Status dataset_read = ReadDataset(state.dataset(), dataset);
  if (!dataset_read.ok()) {
    warnings->push_back("the run's dataset cannot be read (" + dataset_read.message() +
                        "); sft's world frame is used; give --dataset");
    return Status::Ok();
  }
  *found = true;
  return Status::Ok();
}

json Vector(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

json AtlasJson(const UvAtlasReport& r, const BakeReport& b, int texture_size) {
  return {{"texture_size", texture_size},
          {"faces", r.faces},
          {"charts", r.charts},
          {"utilization", r.utilization},
          {"covered_texels_fraction", static_cast<double>(b.covered_texels) /
                                          (static_cast<double>(texture_size) * texture_size)},
          {"max_stretch", r.max_stretch},
          {"mean_stretch", r.mean_stretch},
          {"stretch_definition", "Sander et al. 2001 L2 stretch per chart (1 = isometric)"},
          {"splits", r.splits},
          {"failed_parameterizations", r.failed_parameterizations},
          {"degenerate_faces", r.degenerate_faces},
          {"nonmanifold_edges", r.nonmanifold_edges},
          {"inconsistent_edges", r.inconsistent_edges},
          {"texels_per_unit", r.texels_per_unit},
          {"chart_seconds", r.chart_seconds},
          {"parameterize_seconds", r.parameterize_seconds},
          {"pack_seconds", r.pack_seconds},
          {"atlas_seconds", r.seconds},
          {"bake_seconds", b.seconds},
          {"dilation_rings", b.dilation_rings}};
}

// The textured formats (OBJ + MTL + PNGs and/or glTF binary, Y-up) of an atlas and its textures;
// adds the written files to *files.
Status WriteAtlasFormats(const ExportOptions& options,
                         const std::vector<Eigen::Vector3d>& positions,
                         const std::vector<Eigen::Vector3i>& faces, const UvAtlas& atlas,
                         const BakedMaterial& baked, const Material& material, bool obj, bool gltf,
                         json* files) {
  if (obj) {
    SFT_RETURN_IF_ERROR(WriteObjExport(options.out, positions, faces, atlas, baked, material));
    files->insert(files->end(), {kObjFile, kMtlFile, kAlbedoPngFile, kRoughnessPngFile});
  }
  if (gltf) {
    std::vector<Eigen::Vector3d> y_up(positions.size());
    for (size_t v = 0; v < positions.size(); ++v) {
      y_up[v] = Eigen::Vector3d(positions[v].x(), positions[v].z(), -positions[v].y());
    }
    SFT_RETURN_IF_ERROR(
        WriteGlbExport(JoinPath(options.out, kGlbFile), y_up, faces, atlas, baked, material));
    files->push_back(kGlbFile);
  }
  return Status::Ok();
}

// The textured formats of a material that is UV textures already (a run whose last stage was a
// uv stage): its corner UVs and fitted texels are written as they are, not re-baked.
Status WriteFittedTextures(const ExportOptions& options, const std::vector<Eigen::Vector3i>& faces,
                           const std::vector<Eigen::Vector3d>& positions, const Material& material,
                           bool obj, bool gltf, json* summary, json* files) {
  const UvTexture& albedo = material.uv.albedo;
  const UvTexture& roughness = material.uv.roughness;
  const int n = albedo.width();
  if (albedo.height() != n || roughness.width() != n || roughness.height() != n) {
    return Status::Error(JoinPath(options.reconstruction, "material.json") +
                         ": the UV textures must be square and of one size to export (albedo " +
                         std::to_string(albedo.width()) + "x" + std::to_string(albedo.height()) +
                         ", roughness " + std::to_string(roughness.width()) + "x" +
                         std::to_string(roughness.height()) + ")");
  }
  const UvTexelCharts charts = ComputeUvTexelCharts(faces, material.uv.corner_uvs, n, n);
  UvAtlas atlas;
  atlas.texture_size = n;
  atlas.corner_uv = material.uv.corner_uvs;
  atlas.chart_of_face = charts.chart_of_face;
  atlas.num_charts = charts.num_charts;
  BakedMaterial baked;
  baked.albedo = Image(n, n, 3);
  baked.roughness = Image(n, n, 1);
  baked.coverage = Image(n, n, 1);
  for (int k = 0; k < n * n; ++k) {
    for (int c = 0; c < 3; ++c) baked.albedo.data[3 * k + c] = albedo.texel(k)[c];
    baked.roughness.data[k] = roughness.texel(k)[0];
    baked.coverage.data[k] = charts.used(k) ? 1.0f : 0.0f;
  }
  (*summary)["atlas"] = {{"texture_size", n},
                         {"texture_size_from", "the fitted UV textures (uv stage)"},
                         {"charts", charts.num_charts},
                         {"fitted_texels", charts.used_texels},
                         {"baked", false}};
  if (options.texture_size != 0 && options.texture_size != n) {
    (*summary)["warnings"].push_back("--texture-size " + std::to_string(options.texture_size) +
                                     " ignored: the fitted textures are " + std::to_string(n) +
                                     "² and are written as they are");
  }
  return WriteAtlasFormats(options, positions, faces, atlas, baked, material, obj, gltf, files);
}

// The atlas, the bake and the textured formats (OBJ and/or glTF); adds the atlas's numbers to
// *summary and the written files to *files. `dataset` may be null.
Status WriteTexturedFormats(const ExportOptions& options, const TriMesh& mesh,
                            const std::vector<Eigen::Vector3d>& world,
                            const std::vector<Eigen::Vector3i>& faces,
                            const std::vector<Eigen::Vector3d>& positions, const Material& material,
                            const Dataset* dataset, bool obj, bool gltf, json* summary,
                            json* files) {
  if (material.has_uv_textures()) {
    return WriteFittedTextures(options, faces, positions, material, obj, gltf, summary, files);
  }
  UvAtlasOptions atlas_options = options.atlas;
  std::string texture_from = "--texture-size";
  atlas_options.texture_size = options.texture_size;
  if (options.texture_size == 0) {
    Eigen::Vector3d lo, hi;
    MeshBounds(mesh, &lo, &hi);
    atlas_options.texture_size =
        dataset != nullptr ? TextureSizeFromFootprint(*dataset, 0.5 * (lo + hi), SurfaceArea(mesh))
                           : kDefaultTextureSize;
    texture_from = dataset != nullptr ? "pixel footprint" : "default";
    // Not below what the bake needs to keep the mesh colours' detail (texture_size.h).
    const int faces = static_cast<int>(mesh.n_faces());
    const int bake = TextureSizeForMeshColors(
        faces, std::max(material.albedo.resolution(), material.roughness.resolution()));
    if (bake > atlas_options.texture_size) {
      atlas_options.texture_size = bake;
      texture_from = "mesh-colour density";
    }
  }
  UvAtlas atlas;
  UvAtlasReport atlas_report;
  SFT_RETURN_IF_ERROR(BuildUvAtlas(world, faces, atlas_options, &atlas, &atlas_report)
                          .Prefixed(JoinPath(options.reconstruction, "mesh.ply")));
  BakedMaterial baked;
  BakeReport bake_report;
  SFT_RETURN_IF_ERROR(BakeMaterial(atlas, material, &baked, &bake_report)
                          .Prefixed(JoinPath(options.reconstruction, "material.json")));
  (*summary)["atlas"] = AtlasJson(atlas_report, bake_report, atlas.texture_size);
  (*summary)["atlas"]["texture_size_from"] = texture_from;
  return WriteAtlasFormats(options, positions, faces, atlas, baked, material, obj, gltf, files);
}

}  // namespace

bool ExportOptions::Check(std::string* why) const {
  if (reconstruction.empty()) {
    *why = "reconstruction: required";
    return false;
  }
  if (format != "obj" && format != "gltf" && format != "ply" && format != "all") {
    *why = "format: expected obj, gltf, ply or all, got \"" + format + "\"";
    return false;
  }
  if (texture_size != 0 && (texture_size < 64 || texture_size > 16384)) {
    *why = "texture-size: expected [64, 16384] (or 0 = automatic), got " +
           std::to_string(texture_size);
    return false;
  }
  UvAtlasOptions checked = atlas;
  if (texture_size != 0) checked.texture_size = texture_size;
  return checked.Check(why);
}

namespace {

// Everything after the inputs are read: the frame, the formats and export.json. `dataset` may be
// null (sft's world frame is used).
Status ExportModel(const ExportOptions& options, const TriMesh& mesh, const Material& material,
                   const Dataset* dataset, json warnings,
                   std::chrono::steady_clock::time_point start, json* summary) {
  std::vector<Eigen::Vector3d> world;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, &world, &faces);
  const bool source_frame = dataset != nullptr && dataset->has_source_from_world;
  std::vector<Eigen::Vector3d> positions = world;
  if (source_frame) {
    for (Eigen::Vector3d& p : positions) p = dataset->source_from_world * p;
  }
  const bool obj = options.format == "obj" || options.format == "all";
  const bool gltf = options.format == "gltf" || options.format == "all";
  const bool ply = options.format == "ply" || options.format == "all";
  json files = json::array();
  *summary = {{"reconstruction", options.reconstruction},
              {"frame", source_frame ? "source" : "world"},
              {"gltf_frame", "the export frame turned Z-up to Y-up: (x, y, z) -> (x, z, -y)"},
              {"faces", faces.size()},
              {"vertices", world.size()},
              {"specular", material.specular},
              {"fresnel", material.fresnel == FresnelMode::kSchlick ? "schlick" : "constant"}};
  if (source_frame) {
    const Similarity3d& s = dataset->source_from_world;
    (*summary)["source_from_world"] = {
        {"scale", s.scale},
        {"rotation", {s.rotation.w(), s.rotation.x(), s.rotation.y(), s.rotation.z()}},
        {"translation", Vector(s.translation)}};
  }
  SFT_RETURN_IF_ERROR(MakeDirectories(options.out));

  if (obj || gltf) {
    SFT_RETURN_IF_ERROR(WriteTexturedFormats(options, mesh, world, faces, positions, material,
                                             dataset, obj, gltf, summary, &files));
  }
  if (ply) {
    SFT_RETURN_IF_ERROR(
        WriteColoredPly(JoinPath(options.out, kPlyFile), positions, faces, material));
    files.push_back(kPlyFile);
  }
  files.push_back(kSummaryFile);
  (*summary)["files"] = files;
  if (summary->contains("warnings")) {
    for (const json& w : (*summary)["warnings"]) warnings.push_back(w);
  }
  (*summary)["warnings"] = warnings;
  (*summary)["seconds"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return WriteTextFile(JoinPath(options.out, kSummaryFile), summary->dump(1) + "\n");
}

// RUN/mesh.ply and RUN/material.json (with its mesh-colors or UV texture files).
Status ReadRunModel(const std::string& run, TriMesh* mesh, Material* material) {
  SFT_RETURN_IF_ERROR(ReadMesh(JoinPath(run, "mesh.ply"), mesh));
  return LoadMaterial(JoinPath(run, "material.json"), *mesh, material, MaterialUse::kCheckpoint);
}

}  // namespace

Status ExportReconstruction(const ExportOptions& options, json* summary) {
  const auto start = std::chrono::steady_clock::now();
  std::string why;
  if (!options.Check(&why)) return Status::Error("--" + why);
  SFT_RETURN_IF_ERROR(
      CheckOutputDirectory(options.out, {{options.reconstruction, options.dataset}, {}}, "--out"));
  TriMesh mesh;
  Material material;
  SFT_RETURN_IF_ERROR(ReadRunModel(options.reconstruction, &mesh, &material));
  json warnings = json::array();
  Dataset dataset;
  bool have_dataset = false;
  SFT_RETURN_IF_ERROR(FindDataset(options, &dataset, &have_dataset, &warnings));
  return ExportModel(options, mesh, material, have_dataset ? &dataset : nullptr, warnings, start,
                     summary);
}

Status ExportFinishedRun(const std::string& run, const Dataset& dataset, json* summary) {
  const auto start = std::chrono::steady_clock::now();
  ExportOptions options;
  options.reconstruction = run;
  options.out = JoinPath(run, kRunExportDir);
  TriMesh mesh;
  Material material;
  SFT_RETURN_IF_ERROR(ReadRunModel(run, &mesh, &material));
  return ExportModel(options, mesh, material, &dataset, json::array(), start, summary);
}

}  // namespace sft
