#include "src/capture/calibrated_import.h"

#include <chrono>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>

#include "src/capture/import_files.h"
#include "src/core/progress.h"
#include "src/io/dataset.h"

namespace sft {
namespace {
namespace fs = std::filesystem;

// Masks are carved at most this many pixels along their longer side (halved as often as needed):
// the box needs no finer silhouettes, and memory stays small for long sequences.
constexpr int kMaxCarvingSide = 512;

// The view's mask (8-bit 0/255 at the image's size), or an empty Mat without masks.
Status MakeMask(const CalibratedView& view, const cv::Mat& image,
                const CalibratedImportOptions& opts, cv::Mat* mask) {
  *mask = cv::Mat();
  if (opts.masks.empty()) return Status::Ok();
  if (opts.masks == "threshold") {
    *mask = ThresholdMask(image, opts.threshold);
    return Status::Ok();
  }
  if (opts.masks == "alpha") return AlphaMask(image, view.image, mask);
  if (view.mask_file.empty()) {
    return ReadMaskFile(opts.masks, view.name, image.cols, image.rows, mask);
  }
  cv::Mat grey;
  SFT_RETURN_IF_ERROR(ReadImageAsStored(view.mask_file, cv::IMREAD_GRAYSCALE, &grey));
  if (grey.cols != image.cols || grey.rows != image.rows) {
    return Status::Error(view.mask_file + ": mask is " + std::to_string(grey.cols) + "x" +
                         std::to_string(grey.rows) + " but image " + view.image + " is " +
                         std::to_string(image.cols) + "x" + std::to_string(image.rows));
  }
  cv::threshold(grey, *mask, 127, 255, cv::THRESH_BINARY);  // > 127 = object (docs/dataset.md).
  return Status::Ok();
}

// The view for the object-box search, its mask box-filtered down to at most kMaxCarvingSide
// (the image padded with background to a multiple of 2^k first, so the camera scales exactly).
BoxView CarvingView(const std::string& name, const Camera& camera, const Rigid3d& pose,
                    const cv::Mat& mask) {
  BoxView view;
  view.name = name;
  view.cam_from_world = pose;
  int k = 0;
  while (std::max(camera.width, camera.height) > (kMaxCarvingSide << k)) ++k;
  view.camera = DownscaledCamera(camera, k);
  if (mask.empty()) return view;
  cv::Mat small = mask;
  if (k > 0) {
    const int f = 1 << k;
    cv::Mat padded;
    cv::copyMakeBorder(mask, padded, 0, view.camera.height * f - mask.rows, 0,
                       view.camera.width * f - mask.cols, cv::BORDER_CONSTANT, 0);
    cv::resize(padded, small, cv::Size(view.camera.width, view.camera.height), 0, 0,
               cv::INTER_AREA);
  }
  view.mask = Image(small.cols, small.rows, 1);
  for (int y = 0; y < small.rows; ++y) {
    for (int x = 0; x < small.cols; ++x) view.mask.at(x, y) = small.at<uint8_t>(y, x) > 127;
  }
  return view;
}

// The index of `camera` in dataset->cameras, adding it (id "c<index>") when no equal one exists.
int CameraIndex(const Camera& camera, Dataset* dataset) {
  for (size_t i = 0; i < dataset->cameras.size(); ++i) {
    const Camera& c = dataset->cameras[i];
    if (c.model == camera.model && c.width == camera.width && c.height == camera.height &&
        c.params == camera.params) {
      return static_cast<int>(i);
    }
  }
  Camera added = camera;
  added.id = "c" + std::to_string(dataset->cameras.size());
  dataset->cameras.push_back(added);
  return static_cast<int>(dataset->cameras.size()) - 1;
}

// images/NAME with extension .png (EXR stays .exr); "_<index>" before the extension when two
// views would coincide.
std::string ImageOutputName(const CalibratedView& view, int index, std::set<std::string>* taken) {
  const std::string ext = FileExtension(view.image) == "exr" ? ".exr" : ".png";
  std::string stem = "images/" + WithoutExtension(view.name);
  if (!taken->insert(stem).second) {
    stem += "_" + std::to_string(index);
    taken->insert(stem);
  }
  return stem + ext;
}

// Decodes, masks and stores every view; views with an empty mask are left out.
Status ImportViews(const std::vector<CalibratedView>& views, const CalibratedImportOptions& opts,
                   const std::string& root, Dataset* dataset, std::vector<BoxView>* box_views,
                   CalibratedImportReport* report) {
  std::set<std::string> taken;
  std::vector<std::string> encodings;
  Progress progress("import", static_cast<int64_t>(views.size()), !opts.quiet);
  for (size_t i = 0; i < views.size(); ++i) {
    const CalibratedView& view = views[i];
    std::string why;
    if (!IsContainedRelativePath(view.name, &why)) {
      return Status::Error(view.image + ": output name \"" + view.name + "\": " + why);
    }
    cv::Mat image, mask;
    SFT_RETURN_IF_ERROR(ReadImageAsStored(view.image, cv::IMREAD_UNCHANGED, &image));
    Camera camera;
    SFT_RETURN_IF_ERROR(view.make_camera(image.cols, image.rows, &camera));
    SFT_RETURN_IF_ERROR(MakeMask(view, image, opts, &mask));
    progress.Advance();
    if (!mask.empty() && cv::countNonZero(mask) == 0) {
      if (report->empty_masks++ == 0) report->first_empty_mask = view.name;
      continue;
    }
    ViewSpec spec;
    spec.camera = CameraIndex(camera, dataset);
    spec.camera_id = dataset->cameras[spec.camera].id;
    spec.image = ImageOutputName(view, static_cast<int>(i), &taken);
    spec.cam_from_world = view.cam_from_world;
    std::string encoding;
    SFT_RETURN_IF_ERROR(StoreImportedImage(view.image, image, root, spec.image, &encoding));
    if (std::find(encodings.begin(), encodings.end(), encoding) == encodings.end()) {
      encodings.push_back(encoding);
    }
    if (!mask.empty()) {
      spec.mask = "masks/" + WithoutExtension(spec.image.substr(7)) + ".png";
      SFT_RETURN_IF_ERROR(WritePngMat(JoinPath(root, spec.mask), mask));
    }
    box_views->push_back(CarvingView(spec.image, camera, spec.cam_from_world, mask));
    dataset->views.push_back(spec);
  }
  progress.Finish();
  for (const std::string& e : encodings) {
    report->image_encoding += (report->image_encoding.empty() ? "" : "; ") + e;
  }
  if (dataset->views.empty()) {
    return Status::Error("every view's mask is empty (" + std::to_string(report->empty_masks) +
                         " views, first " + report->first_empty_mask +
                         "): no view shows the object");
  }
  return Status::Ok();
}

Status ImportInto(const std::vector<CalibratedView>& views, const CalibratedSource& source,
                  const CalibratedImportOptions& opts, const std::string& root,
                  CalibratedImportReport* report) {
  Dataset dataset;
  dataset.root = root;
  std::vector<BoxView> box_views;
  SFT_RETURN_IF_ERROR(ImportViews(views, opts, root, &dataset, &box_views, report));
  ObjectBoxOptions box_options = opts.box;
  box_options.quiet = box_options.quiet || opts.quiet;
  SFT_RETURN_IF_ERROR(FindObjectBox(box_views, source.sphere, box_options, &report->box));

  // p_capture = d·p_world + c: the capture's frame centred on the object's box and scaled to a
  // unit diagonal. A camera's translation becomes (t + R·c) / d.
  const Eigen::Vector3d centre = 0.5 * (report->box.lo + report->box.hi);
  const double diagonal = (report->box.hi - report->box.lo).norm();
  if (!(diagonal > 0) || !std::isfinite(diagonal)) {
    return Status::Error("the object's box has zero extent");
  }
  report->diagonal = diagonal;
  report->fill = (report->box.hi - report->box.lo) / diagonal;
  for (ViewSpec& view : dataset.views) {
    Rigid3d& pose = view.cam_from_world;
    pose.translation = (pose.translation + pose.rotation * centre) / diagonal;
  }
  dataset.has_source_from_world = true;
  dataset.source_from_world.scale = diagonal;
  dataset.source_from_world.translation = centre;
  dataset.lighting = "unknown";
  dataset.image_encoding = report->image_encoding;
  const ObjectBox& box = report->box;
  nlohmann::json normalization = {
      {"method", box.method},
      {"fill_ratio", {report->fill.x(), report->fill.y(), report->fill.z()}},
      {"object_box_in_source",
       {{box.lo.x(), box.lo.y(), box.lo.z()}, {box.hi.x(), box.hi.y(), box.hi.z()}}}};
  if (report->empty_masks > 0) normalization["views_left_out_empty_mask"] = report->empty_masks;
  nlohmann::json provenance = {{"from", source.format}};
  if (source.provenance.is_object()) provenance.update(source.provenance);
  provenance["masks"] = report->masks;
  provenance["normalization"] = normalization;
  dataset.extra["import"] = provenance;
  report->views = static_cast<int>(dataset.views.size());
  report->cameras = static_cast<int>(dataset.cameras.size());
  SFT_RETURN_IF_ERROR(WriteSceneJson(dataset, root));
  Dataset check;
  return ReadDataset(root, &check);
}

}  // namespace

bool CalibratedImportOptions::HasMaskFolder() const {
  return !masks.empty() && masks != "threshold" && masks != "alpha";
}

bool CalibratedImportOptions::Check(std::string* why) const {
  if (out.empty()) {
    *why = "--out: required";
    return false;
  }
  if (masks == "auto") {
    *why =
        "--masks auto: GrabCut needs the sparse points of a COLMAP model, which this format "
        "has not; use --masks threshold (a dark background), alpha, or a folder";
    return false;
  }
  std::error_code ec;
  if (HasMaskFolder() && !fs::is_directory(masks, ec)) {
    *why = "--masks: " + masks + ": folder not found (or threshold, alpha)";
    return false;
  }
  return threshold.Check(why) && box.Check(why);
}

Status ImportCalibratedViews(const std::vector<CalibratedView>& views,
                             const CalibratedSource& source, const CalibratedImportOptions& options,
                             CalibratedImportReport* report) {
  const auto start = std::chrono::steady_clock::now();
  *report = CalibratedImportReport();
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  if (views.empty()) return Status::Error("no views to import");
  report->masks = options.masks.empty()     ? "none"
                  : options.HasMaskFolder() ? "folder"
                                            : options.masks;
  RunInputs inputs = source.inputs;
  if (options.HasMaskFolder()) inputs.directories.push_back(options.masks);
  for (const CalibratedView& view : views) inputs.files.push_back(view.image);
  const Status status =
      BuildDatasetFolder(options.out, inputs, options.overwrite, [&](const std::string& partial) {
        return ImportInto(views, source, options, partial, report);
      });
  report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return status;
}

}  // namespace sft
