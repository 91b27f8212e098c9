#include "src/eval/model_viewer.h"

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

#include "src/core/file_util.h"
#include "src/geometry/mesh.h"

namespace sft {
namespace {

// The three.js files the page loads, relative to three_dir, and their names under
// report_files/three/.
struct ThreeFile {
  const char* source;
  const char* target;
};
constexpr ThreeFile kThreeFiles[] = {
    {"three.min.js", "three.min.js"},
    {"examples/js/loaders/GLTFLoader.js", "GLTFLoader.js"},
    {"examples/js/controls/OrbitControls.js", "OrbitControls.js"},
};

// The viewer's script. Placeholders: @GLB@ (base64 GLB), @START_POSITIONS@ and @START_INDICES@
// (base64 little-endian float32 xyz and uint32 triangles; empty = no start view). It writes its
// state into #sft3d-status ("loaded; pixels drawn: result N of M, start N of M" once the views
// show their meshes, or the error), which the headless check (scripts/check_report_viewer.sh)
// reads.
constexpr char kViewerScript[] = R"JS(
(function () {
  var glb = '@GLB@', startPositions = '@START_POSITIONS@', startIndices = '@START_INDICES@';
  var status = document.getElementById('sft3d-status');
  function bytes(b64) {
    var s = atob(b64), a = new Uint8Array(s.length);
    for (var i = 0; i < s.length; ++i) a[i] = s.charCodeAt(i);
    return a.buffer;
  }
  if (typeof THREE === 'undefined' || !THREE.GLTFLoader || !THREE.OrbitControls) {
    status.textContent = 'three.js did not load (report_files/three/)';
    return;
  }
  // One view: a renderer on its canvas, a scene, a camera with orbit controls, three light rigs.
  function View(canvas) {
    var r = new THREE.WebGLRenderer({canvas: canvas, antialias: true, preserveDrawingBuffer: true});
    r.setClearColor(0x202020);
    r.outputEncoding = THREE.sRGBEncoding;
    this.renderer = r;
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(35, canvas.width / canvas.height, 1e-3, 1e3);
    this.scene.add(this.camera);
    this.controls = new THREE.OrbitControls(this.camera, canvas);
    this.rigs = {camera: new THREE.Group(), studio: new THREE.Group(), sky: new THREE.Group()};
    var head = new THREE.DirectionalLight(0xffffff, 0.9);
    head.position.set(0.3, 0.3, 1);
    this.camera.add(head);
    this.camera.add(head.target);
    this.headlight = head;
    var key = new THREE.DirectionalLight(0xfff1e0, 0.9);
    var fill = new THREE.DirectionalLight(0xe0ecff, 0.35);
    var rim = new THREE.DirectionalLight(0xffffff, 0.5);
    key.position.set(1, 1.2, 1); fill.position.set(-1, 0.3, 0.8); rim.position.set(0, 0.8, -1.2);
    this.rigs.studio.add(key, fill, rim, new THREE.AmbientLight(0xffffff, 0.1));
    this.rigs.sky.add(new THREE.HemisphereLight(0xdde8ff, 0x40301c, 1.0));
    this.rigs.camera.add(new THREE.AmbientLight(0xffffff, 0.15));
    for (var k in this.rigs) this.scene.add(this.rigs[k]);
    var self = this;
    this.controls.addEventListener('change', function () { self.draw(); });
  }
  View.prototype.light = function (name) {
    this.headlight.visible = name === 'camera';
    for (var k in this.rigs) this.rigs[k].visible = k === name;
    this.draw();
  };
  View.prototype.draw = function () { this.renderer.render(this.scene, this.camera); };
  View.prototype.frame = function (box) {
    var c = box.getCenter(new THREE.Vector3()), r = box.getSize(new THREE.Vector3()).length() / 2;
    this.controls.target.copy(c);
    var from = new THREE.Vector3(@FROM@).normalize().multiplyScalar(2.5 * r);
    this.camera.position.copy(c).add(from);
    this.camera.near = r / 100; this.camera.far = r * 100;
    this.camera.updateProjectionMatrix();
    this.controls.update();
  };
  var result = new View(document.getElementById('sft3d-result'));
  var views = [result], start = null;
  if (startPositions !== '') {
    start = new View(document.getElementById('sft3d-start'));
    views.push(start);
    var g = new THREE.BufferGeometry();
    var positions = new Float32Array(bytes(startPositions));
    g.setAttribute('position', new THREE.BufferAttribute(positions, 3));
    g.setIndex(new THREE.BufferAttribute(new Uint32Array(bytes(startIndices)), 1));
    start.scene.add(new THREE.Mesh(g, new THREE.MeshStandardMaterial(
        {color: 0xb0b0b0, roughness: 0.6, metalness: 0, flatShading: true})));
  }
  // The two views follow each other's orbit.
  var syncing = false;
  views.forEach(function (v) {
    v.controls.addEventListener('change', function () {
      if (syncing) return;
      syncing = true;
      views.forEach(function (w) {
        if (w === v) return;
        w.camera.position.copy(v.camera.position);
        w.controls.target.copy(v.controls.target);
        w.controls.update();
      });
      syncing = false;
    });
  });
  var select = document.getElementById('sft3d-light');
  select.addEventListener('change', function () {
    views.forEach(function (v) { v.light(select.value); });
  });
  // Pixels of a view that differ from the background: the headless check's proof of a drawing.
  function drawn(v) {
    var gl = v.renderer.getContext(), w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
    var px = new Uint8Array(4 * w * h), n = 0;
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    for (var i = 0; i < px.length; i += 4) {
      if (Math.abs(px[i] - 32) + Math.abs(px[i + 1] - 32) + Math.abs(px[i + 2] - 32) > 6) ++n;
    }
    return n + ' of ' + w * h;
  }
  new THREE.GLTFLoader().parse(bytes(glb), '', function (gltf) {
    result.scene.add(gltf.scene);
    var box = new THREE.Box3().setFromObject(gltf.scene);
    views.forEach(function (v) { v.frame(box); v.light(select.value); });
    status.textContent = 'loaded; pixels drawn: result ' + drawn(result) +
        (start ? ', start ' + drawn(start) : '');
  }, function (e) { status.textContent = 'model.glb did not load: ' + e; });
})();
)JS";

void ReplaceAll(const std::string& from, const std::string& to, std::string* text) {
  for (size_t at = text->find(from); at != std::string::npos; at = text->find(from, at)) {
    text->replace(at, from.size(), to);
    at += to.size();
  }
}

// The start mesh's positions (float32 xyz, in the GLB's frame) and triangles (uint32) as raw
// little-endian bytes.
Status StartMeshBytes(const std::string& path, const Dataset& dataset, std::string* positions,
                      std::string* indices) {
  TriMesh mesh;
  SFT_RETURN_IF_ERROR(ReadMesh(path, &mesh));
  std::vector<Eigen::Vector3d> world;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, &world, &faces);
  std::vector<float> xyz;
  xyz.reserve(3 * world.size());
  for (const Eigen::Vector3d& w : world) {
    // The export's frame (src/export/export.h), then Z-up to Y-up: (x, y, z) -> (x, z, -y).
    const Eigen::Vector3d p = dataset.has_source_from_world ? dataset.source_from_world * w : w;
    xyz.insert(xyz.end(), {static_cast<float>(p.x()), static_cast<float>(p.z()),
                           static_cast<float>(0.0 - p.y())});  // 0 − y: no −0 for y = 0.
  }
  std::vector<uint32_t> tri;
  tri.reserve(3 * faces.size());
  for (const Eigen::Vector3i& f : faces) {
    for (int k = 0; k < 3; ++k) tri.push_back(static_cast<uint32_t>(f[k]));
  }
  positions->assign(reinterpret_cast<const char*>(xyz.data()), xyz.size() * sizeof(float));
  indices->assign(reinterpret_cast<const char*>(tri.data()), tri.size() * sizeof(uint32_t));
  return Status::Ok();
}

// The direction (GLB frame, Y-up, unit) the two views look at the object from when the page opens:
// back along view 0's optical axis, so the object first appears as the first photograph shows it
// (a fixed direction can show a capture's unseen underside). A dataset without views: a fixed
// three-quarter view. Printed as "x, y, z" for the script.
std::string ViewerFrom(const Dataset& dataset) {
  Eigen::Vector3d from(0.35, 0.25, 1.0);
  if (!dataset.views.empty()) {
    const Eigen::Quaterniond world_from_cam = dataset.views[0].cam_from_world.rotation.conjugate();
    Eigen::Vector3d toward_camera = -(world_from_cam * Eigen::Vector3d::UnitZ());
    if (dataset.has_source_from_world) {
      toward_camera = dataset.source_from_world.rotation * toward_camera;
    }
    from = Eigen::Vector3d(toward_camera.x(), toward_camera.z(), -toward_camera.y());  // Y-up.
  }
  from.normalize();
  // Components below the printed precision as 0, not "-0.000000".
  const auto printed = [](double v) { return std::abs(v) < 5e-7 ? 0.0 : v; };
  char text[96];
  std::snprintf(text, sizeof(text), "%.6f, %.6f, %.6f", printed(from.x()), printed(from.y()),
                printed(from.z()));
  return text;
}

// Copies three.js into report_files/three/; false (no error) when three_dir lacks a file.
Status CopyThreeJs(const std::string& three_dir, const std::string& report_dir, bool* found) {
  *found = false;
  for (const ThreeFile& f : kThreeFiles) {
    if (!FileExists(JoinPath(three_dir, f.source))) return Status::Ok();
  }
  for (const ThreeFile& f : kThreeFiles) {
    std::string text;
    SFT_RETURN_IF_ERROR(ReadTextFile(JoinPath(three_dir, f.source), &text));
    SFT_RETURN_IF_ERROR(
        WriteTextFile(JoinPath(report_dir, std::string("report_files/three/") + f.target), text));
  }
  *found = true;
  return Status::Ok();
}

std::string ImageCell(const std::string& file, const std::string& caption) {
  return "<figure><img src=\"" + HtmlEscape(file) +
         "\" width=\"256\" style=\"image-rendering:pixelated\"><figcaption>" + HtmlEscape(caption) +
         "</figcaption></figure>";
}

}  // namespace

bool ModelViewerOptions::Check(std::string* why) const {
  std::string path_why;
  if (!IsContainedRelativePath(export_dir, &path_why)) {
    *why = "export_dir: " + path_why;
    return false;
  }
  if (width < 64 || width > 4096 || height < 64 || height > 4096) {
    *why = "width, height: expected [64, 4096]";
    return false;
  }
  return true;
}

std::string Base64Encode(const std::string& bytes) {
  static const char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve(4 * ((bytes.size() + 2) / 3));
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t chunk = static_cast<uint8_t>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) chunk |= static_cast<uint8_t>(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) chunk |= static_cast<uint8_t>(bytes[i + 2]);
    out += kAlphabet[(chunk >> 18) & 63];
    out += kAlphabet[(chunk >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(chunk >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kAlphabet[chunk & 63] : '=';
  }
  return out;
}

Status AddModelViewer(const ModelViewerOptions& options, const Dataset& dataset, HtmlReport* html) {
  std::string why;
  if (!options.Check(&why)) return Status::Error("model viewer: " + why);
  html->AddHeading("The result in 3D");
  bool found = false;
  SFT_RETURN_IF_ERROR(CopyThreeJs(options.three_dir, html->dir(), &found));
  const std::string albedo = JoinPath(options.export_dir, "model_albedo.png");
  const std::string roughness = JoinPath(options.export_dir, "model_roughness.png");
  std::string maps = "<div class=\"row\">";
  if (FileExists(JoinPath(html->dir(), albedo))) {
    maps += ImageCell(albedo, "albedo map (sRGB)");
  }
  if (FileExists(JoinPath(html->dir(), roughness))) {
    maps += ImageCell(roughness, "roughness map (linear)");
  }
  maps += "</div>";
  if (!found) {
    html->AddParagraph("No 3D view: three.js is not installed (" + options.three_dir +
                       "; apt-get install libjs-three, which scripts/setup.sh does). The asset is "
                       "in " +
                       options.export_dir + "/.");
    html->AddHtml(maps);
    return Status::Ok();
  }
  std::string glb, start_positions, start_indices;
  SFT_RETURN_IF_ERROR(
      ReadTextFile(JoinPath(JoinPath(html->dir(), options.export_dir), "model.glb"), &glb));
  if (!options.start_mesh.empty()) {
    SFT_RETURN_IF_ERROR(
        StartMeshBytes(options.start_mesh, dataset, &start_positions, &start_indices));
  }
  html->AddParagraph(
      "Drag to orbit, scroll to zoom, right-drag to pan; the two views follow each other. The "
      "result is " +
      options.export_dir +
      "/model.glb (what other programs open; three.js "
      "shades it with its own metallic-roughness BSDF, not sft's, so the look is indicative). "
      "The start mesh is grey.");
  const std::string size = "width=\"" + std::to_string(options.width) + "\" height=\"" +
                           std::to_string(options.height) + "\"";
  std::string section = "<div class=\"row\">";
  if (!start_positions.empty()) {
    section += "<figure><canvas id=\"sft3d-start\" " + size +
               "></canvas><figcaption>start</figcaption></figure>";
  }
  section += "<figure><canvas id=\"sft3d-result\" " + size +
             "></canvas><figcaption>result</figcaption></figure></div>"
             "<p>Lighting: <select id=\"sft3d-light\">"
             "<option value=\"camera\">light at the camera</option>"
             "<option value=\"studio\">studio: key, fill and rim</option>"
             "<option value=\"sky\">sky and ground</option></select> "
             "<span id=\"sft3d-status\">loading…</span></p>";
  for (const ThreeFile& f : kThreeFiles) {
    section += std::string("<script src=\"report_files/three/") + f.target + "\"></script>";
  }
  std::string script = kViewerScript;
  ReplaceAll("@START_POSITIONS@", Base64Encode(start_positions), &script);
  ReplaceAll("@START_INDICES@", Base64Encode(start_indices), &script);
  ReplaceAll("@GLB@", Base64Encode(glb), &script);
  ReplaceAll("@FROM@", ViewerFrom(dataset), &script);
  html->AddHtml(section + "<script>" + script + "</script>" + maps);
  return Status::Ok();
}

}  // namespace sft
