#include "src/optim/mpi_wire.h"

namespace sft {
namespace {

// The options structs are written field by field; a new field must be added here too, or other
// ranks would render without it (and results would depend on the rank count). The sizes below
// are those of the fields written (x86-64, libstdc++).
#if defined(__x86_64__) && defined(__GLIBCXX__)
static_assert(sizeof(DerivativeRequest) == 64, "a DerivativeRequest field: write it below");
static_assert(sizeof(RenderOptions) == 88, "a RenderOptions field: write it below");
static_assert(sizeof(Effects) == 5, "an Effects field: write it below");
#endif

void PutRenderOptions(const RenderOptions& r, ByteWriter* w) {
  CHECK(r.sampling_material == nullptr && r.sampling_environment == nullptr)
      << "detached sampling is not sent to other ranks";
  w->Put(r.spp);
  w->Put(r.bounces);
  w->Put(r.effects);
  w->Put(r.seed);
  w->Put(r.threads);
  w->Put(r.pass);
  w->Put(r.shading);
}

RenderOptions GetRenderOptions(ByteReader* r) {
  RenderOptions o;
  o.spp = r->Get<int>();
  o.bounces = r->Get<int>();
  o.effects = r->Get<Effects>();
  o.seed = r->Get<uint64_t>();
  o.threads = r->Get<int>();
  o.pass = r->Get<RenderPass>();
  o.shading = r->Get<Shading>();
  return o;
}

void PutRequest(const DerivativeRequest& d, ByteWriter* w) {
  w->Put(d.params);
  w->Put(d.jacobian_rows);
  w->Put(d.primary_edge_ratio);
  w->Put(d.shadow_edge_ratio);
  w->Put(d.secondary_edge_samples);
  w->Put(d.texel_edge_ratio);
  w->Put(d.normal_sliding);
}

DerivativeRequest GetRequest(ByteReader* r) {
  DerivativeRequest d;
  d.params = r->Get<ParameterSelection>();
  d.jacobian_rows = r->Get<bool>();
  d.primary_edge_ratio = r->Get<double>();
  d.shadow_edge_ratio = r->Get<double>();
  d.secondary_edge_samples = r->Get<double>();
  d.texel_edge_ratio = r->Get<double>();
  d.normal_sliding = r->Get<bool>();
  return d;
}

void PutMeshColors(const MeshColors& colors, ByteWriter* w) {
  w->Put<int>(colors.num_faces());
  w->Put<int>(colors.resolution());
  w->Put<int>(colors.channels());
  w->PutVector(colors.values());
}

MeshColors GetMeshColors(ByteReader* r) {
  const int faces = r->Get<int>(), resolution = r->Get<int>(), channels = r->Get<int>();
  MeshColors colors(faces, resolution, channels);
  colors.values() = r->GetVector<double>();
  CHECK_EQ(colors.values().size(), static_cast<size_t>(colors.num_texels()) * channels);
  return colors;
}

void PutImage(const Image& image, ByteWriter* w) {
  w->Put(image.width);
  w->Put(image.height);
  w->Put(image.channels);
  w->PutVector(image.data);
}

Image GetImage(ByteReader* r) {
  Image image;
  image.width = r->Get<int>();
  image.height = r->Get<int>();
  image.channels = r->Get<int>();
  image.data = r->GetVector<float>();
  return image;
}

}  // namespace

std::vector<std::vector<char> > StateParts(const RenderState& s) {
  std::vector<std::vector<char> > parts(kNumParts);
  ByteWriter scene, positions, material, settings, environment;
  scene.Put(s.scene_id);
  scene.PutVector(s.build_positions);
  scene.PutVector(s.faces);
  positions.PutVector(s.positions);
  CHECK(!s.material.has_uv_textures()) << "UV-texture materials are not fitted";
  PutMeshColors(s.material.albedo, &material);
  PutMeshColors(s.material.roughness, &material);
  material.Put(s.material.specular);
  material.Put(s.material.fresnel);
  settings.PutVector(s.light_scales);
  settings.PutVector(s.light_positions);
  settings.PutVector(s.light_directions);
  settings.PutVector(s.environment_rotations);
  settings.PutVector(s.pose_corrections);
  PutRenderOptions(s.render, &settings);
  PutRequest(s.request, &settings);
  settings.Put(s.layout);
  settings.Put(s.image_scale_log2);
  settings.PutVector(s.view_indices);
  PutImage(s.environment, &environment);
  environment.Put(s.environment_frame);
  parts[kScenePart] = std::move(scene.bytes());
  parts[kPositionsPart] = std::move(positions.bytes());
  parts[kMaterialPart] = std::move(material.bytes());
  parts[kSettingsPart] = std::move(settings.bytes());
  parts[kEnvironmentPart] = std::move(environment.bytes());
  return parts;
}

void ApplyStatePart(int part, const std::vector<char>& bytes, RenderState* s) {
  ByteReader r(bytes);
  switch (part) {
    case kScenePart:
      s->scene_id = r.Get<int64_t>();
      s->build_positions = r.GetVector<Eigen::Vector3d>();
      s->faces = r.GetVector<Eigen::Vector3i>();
      break;
    case kPositionsPart:
      s->positions = r.GetVector<Eigen::Vector3d>();
      break;
    case kMaterialPart:
      s->material.albedo = GetMeshColors(&r);
      s->material.roughness = GetMeshColors(&r);
      s->material.specular = r.Get<double>();
      s->material.fresnel = r.Get<FresnelMode>();
      break;
    case kSettingsPart:
      s->light_scales = r.GetVector<double>();
      s->light_positions = r.GetVector<Eigen::Vector3d>();
      s->light_directions = r.GetVector<Eigen::Vector3d>();
      s->environment_rotations = r.GetVector<Eigen::Vector3d>();
      s->pose_corrections = r.GetVector<PoseDelta>();
      s->render = GetRenderOptions(&r);
      s->request = GetRequest(&r);
      s->layout = r.Get<ParameterLayout>();
      s->image_scale_log2 = r.Get<int>();
      s->view_indices = r.GetVector<int>();
      break;
    case kEnvironmentPart:
      s->environment = GetImage(&r);
      s->environment_frame = r.Get<LightFrame>();
      break;
  }
}

void PutResult(const ViewResult& result, double ready_seconds, ByteWriter* w) {
  PutImage(result.image, w);
  w->Put(result.rows.width);
  w->Put(result.rows.height);
  w->PutVector(result.rows.offsets);
  w->PutVector(result.rows.entries);
  w->PutVector(result.gradient);
  w->Put(result.non_finite);
  w->Put(result.seconds);
  w->Put(ready_seconds);
}

void GetResult(const std::vector<char>& bytes, ViewResult* result, double* ready_seconds) {
  ByteReader r(bytes);
  result->image = GetImage(&r);
  result->rows.width = r.Get<int>();
  result->rows.height = r.Get<int>();
  result->rows.offsets = r.GetVector<uint64_t>();
  result->rows.entries = r.GetVector<JacobianEntry>();
  result->gradient = r.GetVector<double>();
  result->non_finite = r.Get<int64_t>();
  result->seconds = r.Get<double>();
  *ready_seconds = r.Get<double>();
}

}  // namespace sft
