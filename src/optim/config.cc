#include "src/optim/config.h"

#include <cmath>
#include <functional>
#include <map>

#include "src/core/file_util.h"

namespace sft {
namespace {

using json = nlohmann::json;

// One configuration key: how to apply a JSON value (returns "" or what is wrong) and read it back.
struct Key {
  std::function<std::string(const json&, ReconstructOptions*)> set;
  std::function<json(const ReconstructOptions&)> get;
};

Key Int(std::function<int&(ReconstructOptions*)> field, int lo, int hi) {
  return {[field, lo, hi](const json& v, ReconstructOptions* o) -> std::string {
            if (!v.is_number_integer() || v.get<int64_t>() < lo || v.get<int64_t>() > hi) {
              return "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                     "]";
            }
            field(o) = v.get<int>();
            return "";
          },
          [field](const ReconstructOptions& o) {
            return json(field(const_cast<ReconstructOptions*>(&o)));
          }};
}

Key Real(std::function<double&(ReconstructOptions*)> field, double lo, double hi) {
  return {[field, lo, hi](const json& v, ReconstructOptions* o) -> std::string {
            if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < lo ||
                v.get<double>() > hi) {
              return "expected a number in [" + json(lo).dump() + ", " + json(hi).dump() + "]";
            }
            field(o) = v.get<double>();
            return "";
          },
          [field](const ReconstructOptions& o) {
            return json(field(const_cast<ReconstructOptions*>(&o)));
          }};
}

Key Bool(std::function<bool&(ReconstructOptions*)> field) {
  return {[field](const json& v, ReconstructOptions* o) -> std::string {
            if (!v.is_boolean()) return "expected true or false";
            field(o) = v.get<bool>();
            return "";
          },
          [field](const ReconstructOptions& o) {
            return json(field(const_cast<ReconstructOptions*>(&o)));
          }};
}

// A string key with parse/print functions.
Key Choice(std::function<std::string(const std::string&, ReconstructOptions*)> parse,
           std::function<std::string(const ReconstructOptions&)> print) {
  return {[parse](const json& v, ReconstructOptions* o) -> std::string {
            if (!v.is_string()) return "expected a string";
            return parse(v.get<std::string>(), o);
          },
          [print](const ReconstructOptions& o) { return json(print(o)); }};
}

std::string LinearSolverName(ceres::LinearSolverType type) {
  switch (type) {
    case ceres::CGNR:
      return "cgnr";
    case ceres::SPARSE_NORMAL_CHOLESKY:
      return "sparse_normal_cholesky";
    case ceres::DENSE_QR:
      return "dense_qr";
    default:
      return "other";
  }
}

const std::map<std::string, Key>& Keys() {
  using O = ReconstructOptions;
  static const std::map<std::string, Key> keys = {
      {"spp", Int([](O* o) -> int& { return o->cache.render.spp; }, 1, 1 << 20)},
      {"bounces", Int([](O* o) -> int& { return o->cache.render.bounces; }, 1, 16)},
      {"threads", Int([](O* o) -> int& { return o->cache.render.threads; }, 0, 1024)},
      {"effects", Choice(
                      [](const std::string& s, O* o) -> std::string {
                        // "auto": every effect is a candidate and the planner chooses.
                        o->planner.enabled = s == "auto";
                        if (o->planner.enabled) {
                          o->cache.render.effects = Effects();
                          return "";
                        }
                        std::string why;
                        if (Effects::Parse(s, &o->cache.render.effects, &why)) return "";
                        // Parse names the field itself ("effects: unknown effect ...").
                        return why.rfind("effects: ", 0) == 0 ? why.substr(9) : why;
                      },
                      [](const O& o) {
                        return o.planner.enabled ? std::string("auto")
                                                 : o.cache.render.effects.ToString();
                      })},
      {"pin",
       {[](const json& v, O* o) -> std::string {
          if (!v.is_object()) return "expected an object of effect names and true/false";
          o->planner.pins.clear();
          for (const auto& [name, on] : v.items()) {
            if (!on.is_boolean()) return name + ": expected true or false";
            o->planner.pins[name] = on.get<bool>();
          }
          std::string why;
          if (o->planner.Check(&why)) return "";
          return why.rfind("pin: ", 0) == 0 ? why.substr(5) : why;
        },
        [](const O& o) {
          json pins = json::object();
          for (const auto& [name, on] : o.planner.pins) pins[name] = on;
          return pins;
        }}},
      {"planner_views", Int([](O* o) -> int& { return o->planner.views; }, 1, 1000)},
      {"planner_noise_factor",
       Real([](O* o) -> double& { return o->planner.noise_factor; }, 0, 100)},
      {"planner_max_share", Real([](O* o) -> double& { return o->planner.max_share; }, 0, 1)},
      {"shading", Choice(
                      [](const std::string& s, O* o) -> std::string {
                        if (s != "auto" && s != "flat" && s != "smooth")
                          return "expected auto, flat or smooth";
                        o->shading = s;
                        return "";
                      },
                      [](const O& o) { return o.shading; })},
      {"pyramid_levels", Int([](O* o) -> int& { return o->cache.pyramid_levels; }, 1, 12)},
      {"level_weight", Real([](O* o) -> double& { return o->cache.level_weight; }, 1e-6, 64)},
      {"image_weight", Real([](O* o) -> double& { return o->cache.image_weight; }, 0, 1e6)},
      {"laplacian_target", Choice(
                               [](const std::string& s, O* o) -> std::string {
                                 if (s != "displacement" && s != "shape")
                                   return "expected displacement or shape";
                                 o->regularizers.laplacian_of_shape = s == "shape";
                                 return "";
                               },
                               [](const O& o) {
                                 return std::string(
                                     o.regularizers.laplacian_of_shape ? "shape" : "displacement");
                               })},
      {"image_scale",
       {[](const json& v, O* o) -> std::string {
          // 1, 1/2, 1/4, ... 1/64 exactly (powers of two are exact in binary).
          for (int k = 0; k <= 6; ++k) {
            if (v.is_number() && v.get<double>() == std::ldexp(1.0, -k)) {
              o->cache.image_scale_log2 = k;
              return "";
            }
          }
          return "expected 1, 0.5, 0.25, 0.125, 0.0625, 0.03125 or 0.015625";
        },
        [](const O& o) { return json(std::ldexp(1.0, -o.cache.image_scale_log2)); }}},
      {"pyramid_filter",
       Choice(
           [](const std::string& s, O* o) -> std::string {
             return PyramidFilterFromName(s, &o->cache.pyramid_filter) ? ""
                                                                       : "expected box or binomial";
           },
           [](const O& o) { return std::string(PyramidFilterName(o.cache.pyramid_filter)); })},
      {"image_loss",
       Choice(
           [](const std::string& s, O* o) -> std::string {
             return ImageLossFromName(s, &o->cache.image_loss) ? "" : "expected l2 or relative";
           },
           [](const O& o) { return std::string(ImageLossName(o.cache.image_loss)); })},
      {"independent_gradient", Bool([](O* o) -> bool& { return o->cache.independent_gradient; })},
      {"gradient_specular", Bool([](O* o) -> bool& { return o->cache.gradient_specular; })},
      {"mask_dilation", Int([](O* o) -> int& { return o->cache.mask_dilation; }, 0, 64)},
      {"primary_edge_ratio",
       Real([](O* o) -> double& { return o->cache.edges.primary_edge_ratio; }, 0, 16)},
      {"shadow_edge_ratio",
       Real([](O* o) -> double& { return o->cache.edges.shadow_edge_ratio; }, 0, 16)},
      {"secondary_edge_samples",
       Real([](O* o) -> double& { return o->cache.edges.secondary_edge_samples; }, 0, 16)},
      {"texel_edge_ratio",
       Real([](O* o) -> double& { return o->cache.edges.texel_edge_ratio; }, 0, 16)},
      {"superset_renders", Int([](O* o) -> int& { return o->problem.superset_renders; }, 1, 8)},
      {"roughness_min",
       Real([](O* o) -> double& { return o->problem.bounds.roughness_min; }, 0, 0.99)},
      {"solver", Choice(
                     [](const std::string& s, O* o) -> std::string {
                       return SolverKindFromName(s, &o->solver.kind)
                                  ? ""
                                  : "expected lm, dogleg, lbfgs or adam";
                     },
                     [](const O& o) { return std::string(SolverKindName(o.solver.kind)); })},
      {"steps", Int([](O* o) -> int& { return o->solver.steps; }, 1, 1000)},
      {"linear_solver",
       Choice(
           [](const std::string& s, O* o) -> std::string {
             ceres::LinearSolverType& t = o->solver.trust_region.linear_solver_type;
             if (s == "cgnr") {
               t = ceres::CGNR;
             } else if (s == "sparse_normal_cholesky") {
               t = ceres::SPARSE_NORMAL_CHOLESKY;
             } else if (s == "dense_qr") {
               t = ceres::DENSE_QR;
             } else {
               return "expected cgnr, sparse_normal_cholesky or dense_qr";
             }
             return "";
           },
           [](const O& o) { return LinearSolverName(o.solver.trust_region.linear_solver_type); })},
      {"max_linear_solver_iterations",
       Int([](O* o) -> int& { return o->solver.trust_region.max_linear_solver_iterations; }, 1,
           10000)},
      {"initial_trust_region_radius",
       Real([](O* o) -> double& { return o->solver.trust_region.initial_trust_region_radius; },
            1e-12, 1e16)},
      {"solver_threads",
       Int([](O* o) -> int& { return o->solver.trust_region.num_threads; }, 1, 1024)},
      {"lbfgs_rank",
       Int([](O* o) -> int& { return o->solver.line_search.max_lbfgs_rank; }, 1, 1000)},
      {"adam_lr_vertices",
       Real([](O* o) -> double& { return o->solver.adam.learning_rate_vertices; }, 1e-12, 10)},
      {"adam_lr_material",
       Real([](O* o) -> double& { return o->solver.adam.learning_rate_material; }, 1e-12, 10)},
      {"adam_large_steps",
       Real([](O* o) -> double& { return o->solver.adam.large_steps_lambda; }, 0, 1e4)},
      {"adam_uniform", Bool([](O* o) -> bool& { return o->solver.adam.uniform_vertices; })},
      {"adam_resample", Bool([](O* o) -> bool& { return o->solver.adam.resample; })},
      {"adam_average", Real([](O* o) -> double& { return o->solver.adam.average_tail; }, 0, 0.999)},
      {"adam_views_per_step",
       Int([](O* o) -> int& { return o->solver.adam.views_per_step; }, 0, 100000)},
      {"laplacian_weight",
       Real([](O* o) -> double& { return o->regularizers.laplacian_weight; }, 0, 1e12)},
      {"laplacian", Choice(
                        [](const std::string& s, O* o) -> std::string {
                          if (s != "uniform" && s != "cotangent") {
                            return "expected uniform or cotangent";
                          }
                          o->regularizers.cotangent = s == "cotangent";
                          return "";
                        },
                        [](const O& o) {
                          return std::string(o.regularizers.cotangent ? "cotangent" : "uniform");
                        })},
      {"orientation_weight",
       Real([](O* o) -> double& { return o->regularizers.orientation_weight; }, 0, 1e12)},
      {"orientation_min_fraction",
       Real([](O* o) -> double& { return o->regularizers.orientation_min_fraction; }, 1e-6, 0.999)},
      {"proximal_weight",
       Real([](O* o) -> double& { return o->regularizers.proximal_weight; }, 0, 1e12)},
      {"proximal_lambda",
       Real([](O* o) -> double& { return o->regularizers.proximal_lambda; }, 0, 1e6)},
      {"albedo_smoothness",
       Real([](O* o) -> double& { return o->regularizers.albedo_smoothness; }, 0, 1e12)},
      {"roughness_smoothness",
       Real([](O* o) -> double& { return o->regularizers.roughness_smoothness; }, 0, 1e12)},
      {"phases", Choice(
                     [](const std::string& s, O* o) -> std::string {
                       return PhaseScheduleFromName(s, &o->phases)
                                  ? ""
                                  : "expected texture, geometry or alternate";
                     },
                     [](const O& o) { return std::string(PhaseScheduleName(o.phases)); })},
      {"outer_iterations", Int([](O* o) -> int& { return o->outer_iterations; }, 1, 10000)},
      {"normal_sliding", Bool([](O* o) -> bool& { return o->cache.edges.normal_sliding; })},
      {"fit_albedo", Bool([](O* o) -> bool& { return o->fit_albedo; })},
      {"fit_roughness", Bool([](O* o) -> bool& { return o->fit_roughness; })},
      {"fit_specular", Bool([](O* o) -> bool& { return o->fit_specular; })},
      {"fit_lights", Bool([](O* o) -> bool& { return o->fit_lights; })},
      {"fit_light_positions", Bool([](O* o) -> bool& { return o->fit_light_positions; })},
      {"fit_light_directions", Bool([](O* o) -> bool& { return o->fit_light_directions; })},
      {"fit_environment_rotation", Bool([](O* o) -> bool& { return o->fit_environment_rotation; })},
      {"fit_exposure", Bool([](O* o) -> bool& { return o->fit_exposure; })},
      {"fit_poses", Bool([](O* o) -> bool& { return o->fit_poses; })},
      {"exposure_prior",
       Real([](O* o) -> double& { return o->regularizers.exposure_prior; }, 0, 1e12)},
      {"pose_prior",
       {[](const json& v, O* o) -> std::string {
          if (v.is_string() && v.get<std::string>() == "auto") {
            o->regularizers.pose_prior = kPosePriorAuto;
            return "";
          }
          if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < 0 ||
              v.get<double>() > 1e12) {
            return "expected \"auto\" or a number in [0, 1e12]";
          }
          o->regularizers.pose_prior = v.get<double>();
          return "";
        },
        [](const O& o) {
          return o.regularizers.pose_prior == kPosePriorAuto ? json("auto")
                                                             : json(o.regularizers.pose_prior);
        }}},
      {"fit_environment", Bool([](O* o) -> bool& { return o->fit_environment; })},
      {"environment_smoothness",
       Real([](O* o) -> double& { return o->regularizers.environment_smoothness; }, 0, 1e12)},
      {"seed",
       {[](const json& v, O* o) -> std::string {
          if (!v.is_number_integer() || (!v.is_number_unsigned() && v.get<int64_t>() < 0)) {
            return "expected a non-negative integer";
          }
          o->seed = v.get<uint64_t>();
          return "";
        },
        [](const O& o) { return json(o.seed); }}},
      {"views",
       {[](const json& v, O* o) -> std::string {
          if (!v.is_array()) return "expected an array of view indices";
          o->views.clear();
          for (const json& e : v) {
            if (!e.is_number_integer()) return "expected an array of view indices";
            o->views.push_back(e.get<int>());
          }
          return "";
        },
        [](const O& o) { return json(o.views); }}},
  };
  return keys;
}

}  // namespace

Status ApplyReconstructConfig(const json& config, const std::string& source,
                              ReconstructOptions* options) {
  if (!config.is_object()) return Status::Error(source + ": expected a JSON object");
  const auto& keys = Keys();
  for (const auto& [name, value] : config.items()) {
    const auto it = keys.find(name);
    if (it == keys.end()) {
      return Status::Error(source + ": " + name +
                           ": unknown key (the keys are listed in docs/reconstruct.md)");
    }
    const std::string why = it->second.set(value, options);
    if (!why.empty()) return Status::Error(source + ": " + name + ": " + why);
  }
  return Status::Ok();
}

Status ReadReconstructConfig(const std::string& path, ReconstructOptions* options) {
  std::string text;
  SFT_RETURN_IF_ERROR(ReadTextFile(path, &text));
  const json config = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (config.is_discarded()) return Status::Error(path + ": not valid JSON");
  return ApplyReconstructConfig(config, path, options);
}

json ReconstructConfigJson(const ReconstructOptions& options) {
  json config = json::object();
  for (const auto& [name, key] : Keys()) config[name] = key.get(options);
  return config;
}

}  // namespace sft
