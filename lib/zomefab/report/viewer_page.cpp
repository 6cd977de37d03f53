// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/report/viewer_page.h"

#include <filesystem>

#include "zomefab/io/file_io.h"
#include "zomefab/io/glb_write.h"
#include "zomefab/report/detail/html.h"

namespace zomefab::report {

namespace detail {
extern const char* const kThreeMinJs;  // three_js.cpp, generated from libjs-three (web/embed_js.cmake)
extern const char* const kGltfLoaderJs;
extern const char* const kOrbitControlsJs;
}  // namespace detail

namespace {

using detail::escapeHtml;

/// The page's own script: decode the inlined GLB, show it, and let the slider play the mounting steps.
/// It logs "zomefab viewer: ready ..." on the console when the scene is drawn (the tests wait for it).
constexpr const char* kViewerScript = R"js(
(function () {
  'use strict';
  const status = document.getElementById('status');
  function fail(message) {
    status.textContent = 'Cannot show the preview: ' + message;
    console.error('zomefab viewer: ' + message);
  }
  if (!window.WebGLRenderingContext) { fail('this browser has no WebGL'); return; }
  const text = document.getElementById('scene-glb').textContent.trim();
  const binary = atob(text);
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);

  const renderer = new THREE.WebGLRenderer({antialias: true, preserveDrawingBuffer: true});
  renderer.setPixelRatio(window.devicePixelRatio);
  renderer.setSize(window.innerWidth, window.innerHeight);
  renderer.gammaOutput = true;  // three.js r111: the scene's linear colours shown as sRGB
  renderer.gammaFactor = 2.2;
  document.body.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf2f2f2);
  const camera = new THREE.PerspectiveCamera(35, window.innerWidth / window.innerHeight, 0.001, 100);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x666666, 0.9));
  const sun = new THREE.DirectionalLight(0xffffff, 0.7);
  camera.add(sun);
  sun.position.set(0.5, 1, 0.8);
  scene.add(camera);
  const controls = new THREE.OrbitControls(camera, renderer.domElement);
  const render = () => renderer.render(scene, camera);
  controls.addEventListener('change', render);

  new THREE.GLTFLoader().parse(bytes.buffer, '', function (gltf) {
    scene.add(gltf.scene);
    // Frame the object: look at it from the front, a little above, the whole of it in view.
    const box = new THREE.Box3().setFromObject(gltf.scene);
    const size = box.getSize(new THREE.Vector3()), centre = box.getCenter(new THREE.Vector3());
    const radius = 0.5 * size.length();
    const distance = radius / Math.sin(17.5 * Math.PI / 180);  // half the 35° field of view
    camera.position.copy(centre).add(new THREE.Vector3(0.35, 0.35, 1).normalize().multiplyScalar(distance));
    camera.near = distance / 100;
    camera.far = distance * 10;
    camera.updateProjectionMatrix();
    controls.target.copy(centre);
    controls.update();

    // Pieces carry their mounting step in the node extras (docs/preview.md).
    const pieces = [];
    gltf.scene.traverse(function (node) {
      if (node.userData && typeof node.userData.step === 'number' && /^piece-/.test(node.name))
        pieces.push(node);
    });
    const steps = pieces.reduce((m, p) => Math.max(m, p.userData.step), 0);
    const slider = document.getElementById('step');
    const label = document.getElementById('step-label');
    slider.max = String(steps);
    slider.value = String(steps);
    function show() {
      const k = Number(slider.value);
      const now = pieces.filter(p => p.userData.step === k).map(p => p.name);
      pieces.forEach(p => { p.visible = p.userData.step <= k; });
      label.textContent = k === 0 ? 'the frame alone' :
          'step ' + k + ' of ' + steps + (now.length ? ': ' + now.join(' + ') : '');
      render();
    }
    slider.addEventListener('input', show);
    document.getElementById('controls').hidden = steps === 0;
    status.textContent = 'drag to turn, scroll to zoom, right-drag to move';
    show();
    console.log('zomefab viewer: ready, ' + pieces.length + ' pieces in ' + steps + ' steps');
  }, function (error) { fail(error && error.message ? error.message : String(error)); });

  window.addEventListener('resize', function () {
    camera.aspect = window.innerWidth / window.innerHeight;
    camera.updateProjectionMatrix();
    renderer.setSize(window.innerWidth, window.innerHeight);
    render();
  });
})();
)js";

}  // namespace

std::string viewerPage(const std::string& glbBytes, const std::string& title) {
    const std::string name = escapeHtml(title);
    std::string page;
    page.reserve(glbBytes.size() * 4 / 3 + 1200000);
    page += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" + name +
            "</title>\n<style>\nhtml, body { margin: 0; height: 100%; overflow: hidden; background: #f2f2f2;"
            " font: 14px sans-serif; }\n#panel { position: absolute; left: 12px; top: 10px; color: #222;"
            " background: rgba(255,255,255,0.8); padding: 6px 10px; border-radius: 4px; }\n"
            "#panel input { width: 260px; vertical-align: middle; }\n</style>\n</head>\n<body>\n"
            "<div id=\"panel\"><b>" +
            name +
            "</b><br><span id=\"status\">loading…</span>\n<div id=\"controls\">mounting: <input id=\"step\" "
            "type=\"range\" min=\"0\" max=\"0\" value=\"0\"> <span id=\"step-label\"></span></div></div>\n";
    page +=
        "<!-- three.js r111 (https://threejs.org), MIT licence, Copyright © 2010-2019 three.js authors; "
        "from Debian's libjs-three. -->\n<script>\n";
    page += detail::kThreeMinJs;
    page += "\n</script>\n<script>\n";
    page += detail::kGltfLoaderJs;
    page += "\n</script>\n<script>\n";
    page += detail::kOrbitControlsJs;
    page += "\n</script>\n<script id=\"scene-glb\" type=\"application/octet-stream\">\n";
    page += base64Encode(glbBytes);
    page += "\n</script>\n<script>";
    page += kViewerScript;
    page += "</script>\n</body>\n</html>\n";
    return page;
}

void writeViewer(const PreviewInput& input, const PreviewOptions& options, const std::string& path) {
    PreviewOptions plain = options;
    plain.isPieceDracoCompressed = false;
    const std::string glb = serializeGlb(buildPreviewScene(input, plain), plain.glb);
    std::string title = "zomefab preview";
    if (input.extras.is_object() && input.extras.contains("source") && input.extras["source"].is_string())
        title += ": " + std::filesystem::path(input.extras["source"].get<std::string>()).filename().string();
    const std::string page = viewerPage(glb, title);
    writeOutputAtomic(path, [&](std::ostream& out) { out.write(page.data(), std::streamsize(page.size())); });
}

}  // namespace zomefab::report
