#pragma once

// Internal to render/: GLSL 3.3 sources of ViewSynthesizer (new_view.cpp).

namespace orthoface::render::shaders {

// Source depth maps: linear depth (z_cam - near) / (far - near) in a depth texture.
inline const char* kSourceDepthVertex = R"(#version 330 core
layout(location = 0) in vec3 pos;
uniform mat4 clip_from_head;
uniform vec4 zrow;
out float v_z;
void main() {
  gl_Position = clip_from_head * vec4(pos, 1.0);
  v_z = dot(zrow, vec4(pos, 1.0));
})";

inline const char* kSourceDepthFragment = R"(#version 330 core
in float v_z;
uniform vec2 zrange;
void main() { gl_FragDepth = (v_z - zrange.x) / (zrange.y - zrange.x); })";

// New view. Per vertex: where each source camera sees the point (camera coordinates), its z_cam
// and the facing cosines, all affine in the point so they interpolate exactly (perspective-
// correct); per fragment: distortion, visibility, blend weights and two bilinear photo samples.
inline const char* kViewVertex = R"(
layout(location = 0) in vec3 pos;
layout(location = 1) in vec3 nrm;
layout(location = 4) in vec3 seen;  // visible in source 0, 1; the face (1) or the hull (0)
layout(location = 5) in float turn;  // how much the vertex turns with the head (1: fully)
uniform mat4 clip_from_head;
uniform vec4 twist;        // the body's turn back: axis (xyz), angle (w, radians)
uniform vec3 twist_pivot;  // ... about this point
// The body's colours: the front photo where it sees this point (identity), or in a view drawn
// as its mirror image where it sees the point's mirror image (the body stays unmirrored).
uniform mat4 body_from_head;
uniform mat4 src_from_head[2];
uniform int persp[3];  // the front (0) and side (1) cameras, and the new view (2)
uniform vec3 centre[3];
uniform vec3 toward[3];
out vec3 v_q0;
out vec3 v_q0b;  // the front camera's view of where the body takes its colour
out vec3 v_q1;
out vec2 v_z;
out vec2 v_cos;
out vec2 v_seen;
out float v_face;
out float v_body;      // the share of the body's turn back the point takes (0 on the head)
out float v_cos_view;  // the new view's facing cosine
#ifdef MIRROR
uniform mat4 mirror;  // head -> head reflection through the mid-sagittal plane
out vec3 v_q2;        // the side camera's view of the point's mirror image
out vec2 v_mirror;    // its z_cam and facing cosine
#endif
vec3 q(int i, vec3 pc) { return persp[i] == 1 ? pc : vec3(pc.xy, 1.0); }
float facing(int i, vec3 p, vec3 n) {
  return dot(n, persp[i] == 1 ? normalize(centre[i] - p) : toward[i]);
}
// v turned by angle a about the unit axis k (Rodrigues).
vec3 turned(vec3 v, float a) {
  vec3 k = twist.xyz;
  float c = cos(a), s = sin(a);
  return v * c + cross(k, v) * s + k * dot(k, v) * (1.0 - c);
}
void main() {
  // The view draws the point where its share of the body's turn back puts it; the photos are
  // sampled where the point is.
  float a = (1.0 - turn) * twist.w;
  v_body = twist.w != 0.0 ? 1.0 - turn : 0.0;
  vec3 drawn = twist_pivot + turned(pos - twist_pivot, a);
  gl_Position = clip_from_head * vec4(drawn, 1.0);
  vec3 p0 = (src_from_head[0] * vec4(pos, 1.0)).xyz;
  vec3 p1 = (src_from_head[1] * vec4(pos, 1.0)).xyz;
  v_q0 = q(0, p0);
  v_q0b = q(0, (src_from_head[0] * (body_from_head * vec4(pos, 1.0))).xyz);
  v_q1 = q(1, p1);
  v_z = vec2(p0.z, p1.z);
  float len = length(nrm);
  vec3 n = len > 0.0 ? nrm / len : vec3(0.0);
  v_cos = vec2(facing(0, pos, n), facing(1, pos, n));
  v_cos_view = facing(2, drawn, turned(n, a));
  v_seen = seen.xy;
  v_face = seen.z;
#ifdef MIRROR
  vec3 pm = (mirror * vec4(pos, 1.0)).xyz;
  vec3 p2 = (src_from_head[1] * vec4(pm, 1.0)).xyz;
  v_q2 = q(1, p2);
  v_mirror = vec2(p2.z, facing(1, pm, mat3(mirror) * n));
#endif
})";

// Specialised by defines in front of this source (llvmpipe evaluates both sides of a branch,
// so choices fixed per rig or per option are made at compile time): VISIBILITY (0: none, for
// triangles no source depth map occludes; 1: per vertex; 2: per pixel), WEIGHTED (else pick),
// ONLY_SOURCE (0 or 1: the triangle takes that photo alone; undefined: the blend), SOURCES_OUT
// (also each photo's colour and availability alone, for floating textures), MIRROR (the side
// photo's mirror image colours the side it never saw), PERSPECTIVE0
// / 1 and DISTORTED0 / 1 (0 or 1, per source camera).
inline const char* kViewFragment = R"(
in vec3 v_q0;
in vec3 v_q0b;
in vec3 v_q1;
in vec2 v_z;
in vec2 v_cos;
in vec2 v_seen;
in float v_face;
in float v_body;
in float v_cos_view;
#ifdef MIRROR
in vec3 v_q2;
in vec2 v_mirror;
#endif
uniform vec4 intr[2];   // fx fy cx cy
uniform vec2 size[2];   // width height
uniform vec4 dist[2];   // k1 k2 p1 p2
uniform float k3[2];
uniform sampler2D photo0;
uniform sampler2D photo1;
uniform sampler2DShadow zmap0;
uniform sampler2DShadow zmap1;
uniform vec2 zrange[2];  // near far of each source depth map
uniform float tol_mm;
uniform float feather;
uniform float view_bias;  // View blend: the new view's preference for the front photo (0: pick)
uniform float body_side;  // 1, or 0 in a view drawn as its mirror image (body_from_head)
uniform float hull_bias;  // the share of view_bias on the head hull (SynthesisOptions)
uniform float view_bias_mirror;  // ... against the side photo's mirror image
uniform float ramp[2];    // facing cosine over which each photo's share rises from 0 to 1
uniform float ramp_mirror;
uniform float power;
// Hull: a photo's share fades out as its cosine over the view's falls from stretch.y to stretch.x;
// (-2, -1) without a limit: every ratio a point facing the photo has (>= 0) passes.
uniform vec2 stretch;
uniform vec3 fill;
layout(location = 0) out vec4 color;
layout(location = 1) out vec4 weights;
#ifdef SOURCES_OUT
layout(location = 2) out vec4 source0;  // each photo alone, alpha = its availability
layout(location = 3) out vec4 source1;
#endif

vec2 distort(int i, vec2 xy) {  // OpenCV model, as capture::project
  float r2 = dot(xy, xy);
  float radial = 1.0 + r2 * (dist[i].x + r2 * (dist[i].y + r2 * k3[i]));
  return xy * radial + vec2(2.0 * dist[i].z * xy.x * xy.y + dist[i].w * (r2 + 2.0 * xy.x * xy.x),
                            dist[i].z * (r2 + 2.0 * xy.y * xy.y) + 2.0 * dist[i].w * xy.x * xy.y);
}

// Normalised image coordinates of a camera-frame point q (perspective: divided by depth) and
// their pixel (distorted when the camera has distortion). The flags are literals at each call,
// so the unused branch folds away.
vec2 image_xy(vec3 q, bool perspective) { return perspective ? q.xy / q.z : q.xy; }
vec2 image_uv(int i, vec2 xy, bool distorted) {
  return intr[i].zw + intr[i].xy * (distorted ? distort(i, xy) : xy);
}

float inside(vec2 uv, vec2 s) {
  return step(0.0, uv.x) * step(0.0, uv.y) * step(uv.x, s.x) * step(uv.y, s.y);
}

// On the head hull (hair, ears, neck) a photo that sees the surface far more obliquely than the
// new view does would paint it as streaks: its share fades out (SynthesisOptions::
// hull_max_stretch), leaving the other photo or the surroundings' colours. 1 on the face.
float unstretched(float cosine) {
  return mix(smoothstep(stretch.x, stretch.y, cosine / max(v_cos_view, 1e-3)), 1.0, v_face);
}

// Share of source i's view of this point: facing x inside the frame x not occluded x not
// stretched.
// `perspective` is a literal at each call, so the unused side folds away.
float availability(int i, bool perspective, vec2 xy, vec2 uv, float z, float cosine,
                   sampler2DShadow zmap, float vertex_seen) {
  float a = smoothstep(0.0, ramp[i], cosine) * inside(uv, size[i]) * unstretched(cosine);
  if (perspective) a *= step(0.0, z);
#if VISIBILITY == 2
  vec2 und = intr[i].zw + intr[i].xy * xy;
  float px_mm = (perspective ? z : 1.0) / intr[i].x;
  float tol = tol_mm + 1.5 * px_mm / max(cosine, 0.2);
  float ref = (z - tol - zrange[i].x) / (zrange[i].y - zrange[i].x);
  a *= texture(zmap, vec3(und / size[i], ref));  // nearest texel, hard compare (see render_source_depth)
#elif VISIBILITY == 1
  a *= vertex_seen;
#endif
  return a;
}

void main() {
  vec2 xy0 = image_xy(v_q0, PERSPECTIVE0 == 1), uv0 = image_uv(0, xy0, DISTORTED0 == 1);
  vec2 xy1 = image_xy(v_q1, PERSPECTIVE1 == 1), uv1 = image_uv(1, xy1, DISTORTED1 == 1);
  // Where the front photo's colour is read: the body's mostly-unturned part reads it where
  // body_from_head says (one fetch: a switch, not a blend of two places).
  vec2 uv0c = mix(uv0, image_uv(0, image_xy(v_q0b, PERSPECTIVE0 == 1), DISTORTED0 == 1),
                  step(0.5, v_body));
#if defined(ONLY_SOURCE) && ONLY_SOURCE == 0
  // Triangles where the blend below is the front photo alone (ViewSynthesizer sorts them out),
  // its share only cut where it would be stretched.
  float a = unstretched(v_cos.x);
  color = vec4(a * texture(photo0, uv0c / size[0]).rgb + (1.0 - a) * fill, 1.0);
  weights = vec4(a, 0.0, 1.0 - a, v_face);
#elif defined(ONLY_SOURCE) && ONLY_SOURCE == 1
  float a = unstretched(v_cos.y);
  color = vec4(a * texture(photo1, uv1 / size[1]).rgb + (1.0 - a) * fill, 1.0);
  weights = vec4(0.0, a, 1.0 - a, v_face);
#else
  // Alpha = the photo's subject mask (ViewSynthesizer::set_photo_masks; 1 without one).
  vec4 c0 = texture(photo0, uv0c / size[0]), c1 = texture(photo1, uv1 / size[1]);
  float a0 = c0.a * availability(0, PERSPECTIVE0 == 1, xy0, uv0, v_z.x, v_cos.x, zmap0, v_seen.x);
  float a1 = c1.a * availability(1, PERSPECTIVE1 == 1, xy1, uv1, v_z.y, v_cos.y, zmap1, v_seen.y);
  // In a view drawn as its mirror image the body reads the front photo at its mirror image,
  // which the side photo does not see: the side photo gives it nothing (body_side 0).
  a1 *= mix(1.0, body_side, step(0.5, v_body));
  float cos1 = v_cos.y, bias = view_bias;
#ifdef MIRROR
  // The side never photographed: where the side photo does not see the point, its mirror image
  // through the mid-sagittal plane as the side photo shows it (faces are nearly symmetric). No
  // depth test: the mirror image is near, not on, the surface of an asymmetric mesh.
  vec2 xy2 = image_xy(v_q2, PERSPECTIVE1 == 1), uv2 = image_uv(1, xy2, DISTORTED1 == 1);
  vec4 c2 = texture(photo1, uv2 / size[1]);
  float a2 = c2.a * smoothstep(0.0, ramp_mirror, v_mirror.y) * inside(uv2, size[1]);
  if (PERSPECTIVE1 == 1) a2 *= step(0.0, v_mirror.x);
  float m = a2 * (1.0 - a1);
  float a1m = a1 + m;
  c1.rgb = a1m > 0.0 ? (a1 * c1.rgb + m * c2.rgb) / a1m : c1.rgb;
  cos1 = mix(v_mirror.y, v_cos.y, step(0.5, a1));
  bias = mix(view_bias_mirror, view_bias, step(0.5, a1));
  a1 = a1m;
#endif
  // Share of the front photo where both see the point (seed 004 §6).
#ifdef WEIGHTED
  float q0 = pow(max(v_cos.x, 0.0), power), q1 = pow(max(cos1, 0.0), power);
  float pf = q0 + q1 > 0.0 ? q0 / (q0 + q1) : 0.5;
#else
  // The head hull (hair, ears, neck) takes the better-facing photo (seed 004 §6): the view's
  // preference for the front photo keeps the face's registration, but on the hull it paints the
  // front photo's grazing samples as horizontal streaks over what the side photo sees face on.
  // The head hull (hair, ears, neck) keeps hull_bias of that preference: in full it paints the
  // front photo's grazing samples over the hull's sides as horizontal streaks where the side
  // photo sees them face on; none (seed 004's better-facing rule) sets the side photo's hair
  // beside the front photo's face, which real faces show as a seam.
  float pf = smoothstep(-feather, feather, v_cos.x - cos1 + bias * mix(hull_bias, 1.0, v_face));
#endif
  // Where the neck is turned back toward the body's camera (the front camera), the front photo
  // paints it, so it meets the photo's own neck and body without a seam.
  pf = mix(pf, 1.0, v_body);
  float w0 = a0 * (1.0 - a1) + a0 * a1 * pf;
  float w1 = a1 * (1.0 - a0) + a0 * a1 * (1.0 - pf);
  float unseen = (1.0 - a0) * (1.0 - a1);

  color = vec4(w0 * c0.rgb + w1 * c1.rgb + unseen * fill, 1.0);
  weights = vec4(w0, w1, unseen, v_face);
#ifdef SOURCES_OUT
  source0 = vec4(c0.rgb, step(0.5, a0));
  source1 = vec4(c1.rgb, step(0.5, a1));
#endif
#endif
})";

// Colour equalisation of a source photo (render/equalize.h): one triangle covering the target,
// each target pixel = the lookup of the same photo pixel, trilinear between grid nodes; the
// grid is a 2D atlas of n slices of constant blue (x = b * n + r, y = g).
inline const char* kEqualizeVertex = R"(#version 330 core
void main() {
  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(2.0 * p - 1.0, 0.0, 1.0);
})";

inline const char* kEqualizeFragment = R"(#version 330 core
uniform sampler2D photo;
uniform sampler2D lut;
uniform float lut_size;
out vec4 color;
void main() {
  vec4 texel = texelFetch(photo, ivec2(gl_FragCoord.xy), 0);
  vec3 c = texel.rgb;
  float n = lut_size, blue = c.b * (n - 1.0);
  float b0 = min(floor(blue), n - 2.0);
  vec2 rg = c.rg * (n - 1.0) + 0.5;  // texel position inside a slice
  vec2 to_uv = 1.0 / vec2(n * n, n);
  vec3 s0 = texture(lut, (vec2(b0 * n, 0.0) + rg) * to_uv).rgb;
  vec3 s1 = texture(lut, (vec2((b0 + 1.0) * n, 0.0) + rg) * to_uv).rgb;
  color = vec4(mix(s0, s1, blue - b0), texel.a);  // the subject mask passes through
})";

}  // namespace orthoface::render::shaders
