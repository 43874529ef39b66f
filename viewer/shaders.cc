#include "viewer/shaders.h"

namespace parallax::shaders {

const char* const kSurfaceVertex = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
layout(location = 3) in vec3 a_color;  // sRGB in [0, 1] (points); unused for the mesh.
uniform mat4 u_clip_from_world;
uniform mat4 u_cam_from_world;
uniform float u_point_size;
out vec3 v_world;
out vec3 v_normal;
out vec2 v_uv;
out vec3 v_color;
out float v_eye_depth;
// The shadow map's clip coordinates are linear in the position: interpolated, not computed per
// pixel (the link drops them from programs without a shadow map).
uniform mat4 u_shadow_from_world;
out vec4 v_shadow_clip;
invariant gl_Position;  // The depth pre-pass must produce the very same depths.
void main() {
  v_world = a_position;
  v_normal = a_normal;
  v_uv = a_uv;
  v_color = a_color;
  v_eye_depth = (u_cam_from_world * vec4(a_position, 1.0)).z;
  v_shadow_clip = u_shadow_from_world * vec4(a_position, 1.0);
  gl_PointSize = u_point_size;
  gl_Position = u_clip_from_world * vec4(a_position, 1.0);
}
)";

const char* const kSurfaceFragment = R"(
in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;
in vec3 v_color;
in float v_eye_depth;
layout(location = 0) out vec4 o_color;
layout(location = 1) out vec4 o_aux;  // visibility, n.l, eye depth, coverage

// Compile-time constants: one program per combination, so llvmpipe runs no dead branches
// (a single program with uniform switches ran 6x slower).
// 0 atlas, 1 projective, 2 constant grey, 3 vertex color, 4 atlas with the matcap's specular
const int u_albedo_source = ALBEDO_SOURCE;
uniform sampler2D u_matcap;   // Specular by the camera-space normal (BlinnPhongMatcap).
uniform mat4 u_cam_from_world;
uniform sampler2D u_atlas;
uniform bool u_has_atlas;
uniform vec3 u_eye;
uniform vec4 u_light;         // (towards-light direction, 0) or (position, 1)
uniform vec3 u_light_color;  // Irradiance (directional) or intensity (point), linear RGB.
uniform float u_ambient;
uniform float u_specular;
uniform float u_shininess;
uniform float u_exposure;     // Linear scale, 2^stops.

const int u_shadow_mode = SHADOW_MODE;      // 0 none, 1 planar / 4 volume (second pass), 2 map, 3 pcf
uniform sampler2DShadow u_shadow_map;
in vec4 v_shadow_clip;
uniform vec2 u_ndc_to_depth;  // window depth = ndc.z * x + y
const int u_pcf_radius = PCF_RADIUS;
uniform vec4 u_ground;        // Plane (n, d) for the planar shadow pass.
uniform float u_ground_tolerance;

uniform int u_num_projectors;
uniform sampler2D u_photo0;
uniform sampler2D u_photo1;
uniform sampler2D u_photo2;
uniform sampler2DShadow u_projector_depth0;
uniform sampler2DShadow u_projector_depth1;
uniform sampler2DShadow u_projector_depth2;
uniform mat4 u_projector_from_world[3];
uniform vec3 u_projector_centre[3];
uniform vec3 u_projector_gain[3];  // Each photo's color gain: linear RGB to the common exposure.
uniform float u_projector_pull;  // Fraction of the distance, e.g. 0.003.

vec3 SrgbToLinear(vec3 c) {
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(vec3(0.04045), c));
}
vec3 LinearToSrgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}

// 1 lit, 0 shadowed. Hardware comparison gives a bilinearly filtered 0/1 per tap; outside the
// light's frustum the border depth 1 reads as lit.
float ShadowVisibility() {
  vec4 clip = v_shadow_clip;
  if (clip.w <= 0.0) return 1.0;
  vec3 ndc = clip.xyz / clip.w;
  vec3 coord = vec3(ndc.xy * 0.5 + 0.5, ndc.z * u_ndc_to_depth.x + u_ndc_to_depth.y);
  if (u_shadow_mode == 2 || u_pcf_radius == 0) return texture(u_shadow_map, coord);
  // PCF over (2r+1)^2 texels with (2r)^2 taps: each hardware-filtered tap, half a texel off the
  // texel grid, compares 2x2 texels, and together they weigh the square as a tent. 4 taps for
  // r = 1, where whole-texel offsets took 9 (the main cost of a frame on llvmpipe).
  vec2 texel = 1.0 / vec2(textureSize(u_shadow_map, 0));
  float sum = 0.0;
  const int r = u_pcf_radius;
  for (int y = 0; y < 2 * r; ++y) {
    for (int x = 0; x < 2 * r; ++x) {
      vec2 offset = vec2(float(x), float(y)) - float(r) + 0.5;
      sum += texture(u_shadow_map, vec3(coord.xy + offset * texel, coord.z));
    }
  }
  return sum / float(4 * r * r);
}

// A photo projected like a slide: its color and a weight, zero where the projector's depth
// map says the surface is hidden from that camera, or outside its image.
vec4 Project(sampler2D photo, sampler2DShadow depth, mat4 projector_from_world, vec3 centre,
             vec3 gain, vec3 view_dir) {
  vec4 clip = projector_from_world * vec4(v_world, 1.0);
  if (clip.w <= 0.0) return vec4(0.0);
  vec3 ndc = clip.xyz / clip.w;
  if (any(greaterThan(abs(ndc), vec3(1.0)))) return vec4(0.0);
  vec2 uv = ndc.xy * 0.5 + 0.5;
  // Visibility bias relative to the distance: the point is pulled a small fraction of the way
  // towards the projector. A slope-scaled polygon offset would push silhouettes behind the
  // surfaces they hide and let photos of the occluder leak onto them.
  vec4 pulled = projector_from_world * vec4(mix(v_world, centre, u_projector_pull), 1.0);
  float ref = (pulled.z / pulled.w) * u_ndc_to_depth.x + u_ndc_to_depth.y;
  if (texture(depth, vec3(uv, ref)) < 0.5) return vec4(0.0);
  // Views whose ray to the point is close to the eye's ray get the weight.
  float cosine = max(dot(normalize(centre - v_world), view_dir), 0.0);
  float weight = pow(cosine, 64.0) + 1e-6;
  // Photos are stored top row first; t = 1 - v / H flips into texture coordinates.
  vec3 color = texture(photo, vec2(uv.x, 1.0 - uv.y)).rgb * gain;
  return vec4(color * weight, weight);
}

void main() {
  vec3 view_dir = normalize(u_eye - v_world);
  // Points and the mesh's corners carry normals (smooth within a crease angle); where one is
  // missing, the face normal is the cross product of the position's screen derivatives.
  vec3 n = v_normal;
#if ALBEDO_SOURCE == 3
  if (dot(n, n) == 0.0) n = view_dir;
#else
  if (dot(n, n) == 0.0) n = cross(dFdx(v_world), dFdy(v_world));
  if (dot(n, n) == 0.0) n = view_dir;
#endif
  n = normalize(n);
  // Windings of reconstructed meshes are not consistent: light the side the eye sees.
  if (dot(n, view_dir) < 0.0) n = -n;

  vec3 to_light = u_light.xyz;
  vec3 irradiance = u_light_color;
  if (u_light.w > 0.5) {
    to_light = u_light.xyz - v_world;
    float d2 = max(dot(to_light, to_light), 1e-20);
    irradiance /= d2;
  }
  to_light = normalize(to_light);
  float n_dot_l = dot(n, to_light);

  float visibility = 1.0;
  if (u_shadow_mode == 1) {
    // Second pass of planar shadows: redraw only where the ground lies under a flattened caster.
    // Ground is near the plane and faces along its normal: not the foot of a wall.
    float height = dot(u_ground.xyz, v_world) + u_ground.w;
    if (abs(height) > u_ground_tolerance || abs(dot(n, u_ground.xyz)) < 0.7) discard;
    visibility = 0.0;
  } else if (u_shadow_mode == 4) {
    visibility = 0.0;  // Second pass of shadow volumes: the stencil passes shadowed pixels alone.
  } else if (u_shadow_mode == 2 || u_shadow_mode == 3) {
    visibility = ShadowVisibility();
  }

  vec3 albedo = vec3(0.7);
  bool relight = true;
  if (u_albedo_source == 0 || (u_albedo_source == 4 && u_has_atlas)) {
    albedo = texture(u_atlas, v_uv).rgb;  // An sRGB texture: sampling returns linear values.
  } else if (u_albedo_source == 3) {
    albedo = SrgbToLinear(v_color);
  } else if (u_albedo_source == 1) {
    vec4 sum = Project(u_photo0, u_projector_depth0, u_projector_from_world[0], u_projector_centre[0], u_projector_gain[0], view_dir);
    if (u_num_projectors > 1) sum += Project(u_photo1, u_projector_depth1, u_projector_from_world[1], u_projector_centre[1], u_projector_gain[1], view_dir);
    if (u_num_projectors > 2) sum += Project(u_photo2, u_projector_depth2, u_projector_from_world[2], u_projector_centre[2], u_projector_gain[2], view_dir);
    if (sum.w > 0.0) {
      // Photos already hold the scene's lighting and shadows: show them as captured.
      albedo = sum.rgb / sum.w;
      relight = false;
    } else if (u_has_atlas) {
      albedo = texture(u_atlas, v_uv).rgb;  // No photo sees this surface.
    }
  }

  vec3 color = albedo;
  if (relight) {
    float lit = visibility * max(n_dot_l, 0.0);
    vec3 h = normalize(to_light + view_dir);
#if ALBEDO_SOURCE == 4
    vec3 n_camera = mat3(u_cam_from_world) * n;
    float specular = texture(u_matcap, n_camera.xy * 0.5 + 0.5).r;
#else
    float specular = n_dot_l > 0.0 ? u_specular * pow(max(dot(n, h), 0.0), u_shininess) : 0.0;
#endif
    color = albedo * (vec3(u_ambient) + lit * irradiance) + visibility * specular * irradiance;
  }
#if HDR_OUTPUT
  o_color = vec4(color, 1.0);
#else
  o_color = vec4(LinearToSrgb(color * u_exposure), 1.0);
#endif
  o_aux = vec4(visibility, n_dot_l, v_eye_depth, 1.0);
}
)";

const char* const kDepthVertex = R"(#version 330 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_clip_from_world;
uniform float u_point_size;
invariant gl_Position;  // Same depths as the surface shader's, for the pre-pass.
void main() {
  gl_PointSize = u_point_size;
  gl_Position = u_clip_from_world * vec4(a_position, 1.0);
}
)";

const char* const kDepthFragment = R"(#version 330 core
void main() {}
)";

const char* const kPlanarVertex = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 3) in vec3 a_color;  // Mesh: x = the triangle's greatest height.
uniform mat4 u_clip_from_world;
uniform mat4 u_planar_shadow;  // Flattens onto the ground along the light.
uniform vec4 u_ground;
uniform float u_point_size;
uniform bool u_points;
out float v_height;
void main() {
  // Whole triangles cast (the foot of a box too); a point casts by its own height.
  v_height = u_points ? dot(u_ground.xyz, a_position) + u_ground.w : a_color.x;
  gl_PointSize = u_point_size;
  gl_Position = u_clip_from_world * (u_planar_shadow * vec4(a_position, 1.0));
}
)";

const char* const kPlanarFragment = R"(#version 330 core
in float v_height;
uniform float u_ground_tolerance;
void main() {
  // The ground itself (and anything under it) casts no planar shadow onto the ground. The
  // value is constant over a triangle: no fragment of a standing triangle is dropped.
  if (v_height < u_ground_tolerance) discard;
}
)";

const char* const kVolumeVertex = R"(#version 330 core
layout(location = 0) in vec4 a_position;
uniform mat4 u_clip_from_world;
void main() { gl_Position = u_clip_from_world * a_position; }
)";

const char* const kBlobVertex = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 2) in vec2 a_uv;  // Across the blob: [-1, 1]^2.
uniform mat4 u_clip_from_world;
uniform vec3 u_eye;
uniform float u_lift;  // Towards the eye, so the ground's own bumps do not hide the blob.
out vec2 v_st;
void main() {
  v_st = a_uv;
  gl_Position = u_clip_from_world * vec4(a_position + u_lift * normalize(u_eye - a_position), 1.0);
}
)";

const char* const kBlobFragment = R"(#version 330 core
in vec2 v_st;
uniform sampler2D u_blob;
layout(location = 0) out vec4 o_color;
layout(location = 1) out vec4 o_aux;
void main() {
  // Multiplied into the frame (blending): the color darkens, the visibility with it.
  float visibility = texture(u_blob, v_st * 0.5 + 0.5).r;
  o_color = vec4(vec3(visibility), 1.0);
  o_aux = vec4(visibility, 1.0, 1.0, 1.0);
}
)";

const char* const kToneMapVertex = R"(#version 330 core
void main() {
  vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));  // (0,0) (2,0) (0,2)
  gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
)";

const char* const kToneMapFragment = R"(#version 330 core
uniform sampler2D u_hdr;
uniform float u_exposure;
uniform int u_operator;  // 0 clamp, 1 extended Reinhard on luminance, 2 ACES filmic
uniform float u_white;
layout(location = 0) out vec4 o_color;
void main() {
  vec3 c = max(texelFetch(u_hdr, ivec2(gl_FragCoord.xy), 0).rgb * u_exposure, vec3(0.0));
  if (u_operator == 1) {
    float luminance = dot(c, vec3(0.2126, 0.7152, 0.0722));
    float mapped = luminance * (1.0 + luminance / (u_white * u_white)) / (1.0 + luminance);
    c *= luminance > 0.0 ? mapped / luminance : 0.0;
  } else if (u_operator == 2) {
    c = (c * (2.51 * c + 0.03)) / (c * (2.43 * c + 0.59) + 0.14);
  }
  c = clamp(c, 0.0, 1.0);
  o_color = vec4(mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c)), 1.0);
}
)";

const char* const kGlareExcess = R"(
uniform float u_exposure;
uniform float u_white;  // The exposed value the display shows as white.
vec3 Excess(vec3 c) { return max(c - vec3(u_white / u_exposure), vec3(0.0)); }
)";

const char* const kGlareFirstLevelFragment = R"(
uniform sampler2D u_hdr;
layout(location = 0) out vec4 o_excess;
void main() {
  ivec2 size = textureSize(u_hdr, 0);
  vec3 sum = vec3(0.0);
  for (int i = 0; i < 4; ++i) {
    ivec2 p = 2 * ivec2(gl_FragCoord.xy) + ivec2(i & 1, i >> 1);
    if (all(lessThan(p, size))) sum += Excess(max(texelFetch(u_hdr, p, 0).rgb, vec3(0.0)));
  }
  o_excess = vec4(0.25 * sum, 1.0);
}
)";

const char* const kGlareUpsampleFragment = R"(#version 330 core
uniform sampler2D u_coarser;
uniform vec2 u_size;  // This level's.
layout(location = 0) out vec4 o_halo;
void main() { o_halo = vec4(texture(u_coarser, gl_FragCoord.xy / u_size).rgb, 0.0); }
)";

const char* const kGlareCompositeFragment = R"(
uniform sampler2D u_hdr;
uniform sampler2D u_halo;  // The pyramid's first level, every coarser one added to it.
uniform vec2 u_extent;     // The pixels the pyramid covers: the frame padded to a multiple of 64.
uniform float u_levels;
layout(location = 0) out vec4 o_color;
void main() {
  vec3 c = max(texelFetch(u_hdr, ivec2(gl_FragCoord.xy), 0).rgb, vec3(0.0));
  vec3 halo = texture(u_halo, gl_FragCoord.xy / u_extent).rgb / u_levels;
  o_color = vec4(c - Excess(c) + halo, 1.0);
}
)";

const char* const kLineVertex = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 3) in vec3 a_color;  // Linear RGB.
uniform mat4 u_clip_from_world;
out vec3 v_color;
void main() {
  v_color = a_color;
  gl_Position = u_clip_from_world * vec4(a_position, 1.0);
}
)";

const char* const kLineFragment = R"(#version 330 core
in vec3 v_color;
uniform bool u_linear_output;  // Into the float frame.
layout(location = 0) out vec4 o_color;
layout(location = 1) out vec4 o_aux;
void main() {
  vec3 c = clamp(v_color, 0.0, 1.0);
  o_color = u_linear_output ? vec4(c, 1.0)
                            : vec4(mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c)), 1.0);
  o_aux = vec4(1.0, 1.0, 0.0, 0.0);  // Not a surface.
}
)";

}  // namespace parallax::shaders
