#pragma once
// GLSL 3.30 sources of the viewer's programs (raw string literals in shaders.cc).
namespace parallax::shaders {

// Surfaces (mesh triangles and point sprites): Blinn-Phong in linear light, shadow map or PCF,
// projective texturing, exposure, sRGB output; a second output carries light visibility,
// n.l, eye depth and coverage for tests. The fragment shader has no #version line: prefix it
// with "#version 330 core" and #defines of ALBEDO_SOURCE, SHADOW_MODE, PCF_RADIUS and
// HDR_OUTPUT (1: linear light without exposure, for the float frame).
extern const char* const kSurfaceVertex;
extern const char* const kSurfaceFragment;

// Depth only, from a light or a projector; the fragment shader also serves the shadow volumes.
extern const char* const kDepthVertex;
extern const char* const kDepthFragment;

// Geometry flattened onto the ground along the light (planar shadows, stencil marking).
extern const char* const kPlanarVertex;
extern const char* const kPlanarFragment;

// Shadow volumes: homogeneous world points (w = 0 at infinity), counted in the stencil only
// (with kDepthFragment).
extern const char* const kVolumeVertex;

// Blob shadows: a textured quad on the ground per blob, multiplied into the frame.
extern const char* const kBlobVertex;
extern const char* const kBlobFragment;

// Tone mapping: the float frame, exposed and mapped, into the 8-bit sRGB frame (a triangle
// covering the screen, no vertex buffer).
extern const char* const kToneMapVertex;
extern const char* const kToneMapFragment;

// Glare (viewer/glare.h). Neither fragment shader has a #version line: prefix each with
// "#version 330 core" and kGlareExcess, the light a pixel holds over the display's white.
extern const char* const kGlareExcess;
// The excess of 2x2 pixels of the float frame averaged: the first level of the pyramid.
extern const char* const kGlareFirstLevelFragment;
// A coarser level upsampled, to be added to the next finer one (complete, with its #version).
extern const char* const kGlareUpsampleFragment;
// The float frame less its excess, plus the pyramid's levels upsampled and averaged.
extern const char* const kGlareCompositeFragment;

// Colored lines: camera frusta and the ground grid.
extern const char* const kLineVertex;
extern const char* const kLineFragment;

}  // namespace parallax::shaders
