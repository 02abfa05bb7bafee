// The built-in Cornell box.
//
// Geometry and camera: the measured box of the Cornell University Program of Computer
// Graphics, "Cornell Box Data", https://www.graphics.cornell.edu/online/box/data.html
// (all coordinates in millimetres, verbatim from that page; the box is not a perfect cube,
// so several corners differ by a few mm). Camera: position (278, 273, −800), direction
// (0, 0, 1), up (0, 1, 0), focal length 35 mm, film 25 × 25 mm ⇒ vertical field of view
// 2·atan(12.5/35) = 39.3077°.
//
// Colours: the data page gives reflectance spectra (400–700 nm) and the light's emission
// spectrum. We use their published RGB conversion from Mitsuba 3's `mitsuba.cornell_box()`
// scene dictionary (itself after Benedikt Bitterli's "Rendering resources" cornell-box scene):
//   white  diffuse reflectance (0.885809, 0.698859, 0.666422)
//   red    diffuse reflectance (0.570068, 0.0430135, 0.0443706)
//   green  diffuse reflectance (0.105421, 0.37798, 0.076425)
//   light  area emitter radiance (18.387, 13.9873, 6.75357) W·sr⁻¹·m⁻², white bsdf
// Everything is Lambertian, as the data page states.
//
// Orientation: every quad is wound so that its front side (counter-clockwise, see scene.h)
// faces where light can reach it: walls face into the box, block faces face out of the
// block, and the light faces down (−y). The published vertex order is not relied upon; each
// quad is oriented against a reference point below.
#include "core/error.h"
#include "scene/scene.h"

#include <array>

namespace pl {

namespace {

using Quad = std::array<Vec3, 4>;

/// Adds quad (a, b, c, d) as two triangles (a, b, c), (a, c, d), wound so that the front side
/// faces `reference` when facesReference is true and away from it otherwise.
void addQuad(Mesh& mesh, Quad quad, uint32_t material, const Vec3& reference, bool facesReference) {
  const Vec3 normal = glm::cross(quad[1] - quad[0], quad[2] - quad[0]);
  const Vec3 centre = 0.25f * (quad[0] + quad[1] + quad[2] + quad[3]);
  const bool facing = glm::dot(normal, reference - centre) > 0.0f;
  if (facing != facesReference) std::swap(quad[1], quad[3]);  // reverses the winding
  const auto base = uint32_t(mesh.positions.size());
  for (const Vec3& p : quad) mesh.positions.push_back(p);
  mesh.triangles.push_back(UVec3(base, base + 1, base + 2));
  mesh.triangles.push_back(UVec3(base, base + 2, base + 3));
  mesh.materials.push_back(material);
  mesh.materials.push_back(material);
}

/// A block (its four side faces and its top; the bottom rests on the floor and is left out,
/// as in the published data). Faces are oriented away from the block's centre.
void addBlock(Mesh& mesh, const std::array<Quad, 5>& faces, uint32_t material) {
  Vec3 centre(0.0f);
  for (const Quad& face : faces)
    for (const Vec3& p : face) centre += p;
  centre /= 20.0f;
  for (const Quad& face : faces) addQuad(mesh, face, material, centre, false);
}

}  // namespace

Scene makeCornellBox() {
  Scene scene;
  scene.sourcePath = "cornell";

  enum : uint32_t { kWhite, kRed, kGreen, kLight };
  scene.materials.push_back({.name = "white", .bsdf = LambertBsdf{Rgb(0.885809f, 0.698859f, 0.666422f)}});
  scene.materials.push_back({.name = "red", .bsdf = LambertBsdf{Rgb(0.570068f, 0.0430135f, 0.0443706f)}});
  scene.materials.push_back({.name = "green", .bsdf = LambertBsdf{Rgb(0.105421f, 0.37798f, 0.076425f)}});
  scene.materials.push_back({.name = "light",
                             .bsdf = LambertBsdf{Rgb(0.885809f, 0.698859f, 0.666422f)},
                             .emission = Rgb(18.387f, 13.9873f, 6.75357f)});

  // A point well inside the room (the walls face it).
  const Vec3 roomCentre(278.0f, 274.4f, 279.6f);

  Mesh room;
  room.name = "room";
  addQuad(room, {Vec3(552.8f, 0.0f, 0.0f), Vec3(0.0f, 0.0f, 0.0f), Vec3(0.0f, 0.0f, 559.2f), Vec3(549.6f, 0.0f, 559.2f)},
          kWhite, roomCentre, true);  // floor
  addQuad(room,
          {Vec3(556.0f, 548.8f, 0.0f), Vec3(556.0f, 548.8f, 559.2f), Vec3(0.0f, 548.8f, 559.2f), Vec3(0.0f, 548.8f, 0.0f)},
          kWhite, roomCentre, true);  // ceiling
  addQuad(room,
          {Vec3(549.6f, 0.0f, 559.2f), Vec3(0.0f, 0.0f, 559.2f), Vec3(0.0f, 548.8f, 559.2f), Vec3(556.0f, 548.8f, 559.2f)},
          kWhite, roomCentre, true);  // back wall
  addQuad(room, {Vec3(0.0f, 0.0f, 559.2f), Vec3(0.0f, 0.0f, 0.0f), Vec3(0.0f, 548.8f, 0.0f), Vec3(0.0f, 548.8f, 559.2f)},
          kGreen, roomCentre, true);  // right wall (x = 0; +x is to the camera's left)
  addQuad(room,
          {Vec3(552.8f, 0.0f, 0.0f), Vec3(549.6f, 0.0f, 559.2f), Vec3(556.0f, 548.8f, 559.2f), Vec3(556.0f, 548.8f, 0.0f)},
          kRed, roomCentre, true);  // left wall

  // The light: 130 × 105 mm (x 213..343, z 227..332). The data page puts it in the ceiling
  // plane y = 548.8; we lower it by kLightGap so the two surfaces never coincide (coplanar
  // surfaces would make every hit on the light ambiguous). 0.1 mm is far below the 1 mm
  // precision of the measurements.
  constexpr float kLightGap = 0.1f;
  constexpr float lightY = 548.8f - kLightGap;
  Mesh light;
  light.name = "light";
  addQuad(light,
          {Vec3(343.0f, lightY, 227.0f), Vec3(343.0f, lightY, 332.0f), Vec3(213.0f, lightY, 332.0f),
           Vec3(213.0f, lightY, 227.0f)},
          kLight, Vec3(278.0f, 0.0f, 279.5f), true);  // faces down, towards the floor

  Mesh blocks;
  blocks.name = "blocks";
  addBlock(blocks,
           {{{Vec3(130.0f, 165.0f, 65.0f), Vec3(82.0f, 165.0f, 225.0f), Vec3(240.0f, 165.0f, 272.0f), Vec3(290.0f, 165.0f, 114.0f)},
             {Vec3(290.0f, 0.0f, 114.0f), Vec3(290.0f, 165.0f, 114.0f), Vec3(240.0f, 165.0f, 272.0f), Vec3(240.0f, 0.0f, 272.0f)},
             {Vec3(130.0f, 0.0f, 65.0f), Vec3(130.0f, 165.0f, 65.0f), Vec3(290.0f, 165.0f, 114.0f), Vec3(290.0f, 0.0f, 114.0f)},
             {Vec3(82.0f, 0.0f, 225.0f), Vec3(82.0f, 165.0f, 225.0f), Vec3(130.0f, 165.0f, 65.0f), Vec3(130.0f, 0.0f, 65.0f)},
             {Vec3(240.0f, 0.0f, 272.0f), Vec3(240.0f, 165.0f, 272.0f), Vec3(82.0f, 165.0f, 225.0f), Vec3(82.0f, 0.0f, 225.0f)}}},
           kWhite);  // short block
  addBlock(blocks,
           {{{Vec3(423.0f, 330.0f, 247.0f), Vec3(265.0f, 330.0f, 296.0f), Vec3(314.0f, 330.0f, 456.0f), Vec3(472.0f, 330.0f, 406.0f)},
             {Vec3(423.0f, 0.0f, 247.0f), Vec3(423.0f, 330.0f, 247.0f), Vec3(472.0f, 330.0f, 406.0f), Vec3(472.0f, 0.0f, 406.0f)},
             {Vec3(472.0f, 0.0f, 406.0f), Vec3(472.0f, 330.0f, 406.0f), Vec3(314.0f, 330.0f, 456.0f), Vec3(314.0f, 0.0f, 456.0f)},
             {Vec3(314.0f, 0.0f, 456.0f), Vec3(314.0f, 330.0f, 456.0f), Vec3(265.0f, 330.0f, 296.0f), Vec3(265.0f, 0.0f, 296.0f)},
             {Vec3(265.0f, 0.0f, 296.0f), Vec3(265.0f, 330.0f, 296.0f), Vec3(423.0f, 330.0f, 247.0f), Vec3(423.0f, 0.0f, 247.0f)}}},
           kWhite);  // tall block

  scene.meshes.push_back(std::move(room));
  scene.meshes.push_back(std::move(light));
  scene.meshes.push_back(std::move(blocks));

  CameraDesc camera;
  camera.name = "default";
  camera.eye = Vec3(278.0f, 273.0f, -800.0f);
  camera.target = Vec3(278.0f, 273.0f, 0.0f);
  camera.up = Vec3(0.0f, 1.0f, 0.0f);
  camera.fovYDegrees = 39.3077f;
  camera.focusDistance = 800.0f + 279.6f;  // to the middle of the box
  camera.aspectRatio = 1.0f;               // 25 × 25 mm film
  scene.cameras.push_back(camera);
  camera.name = "cornell";
  scene.cameras.push_back(camera);

  scene.finalize();
  return scene;
}

}  // namespace pl
