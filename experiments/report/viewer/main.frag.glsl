uniform sampler2D bf_orig;
uniform vec3 u_light;
uniform float u_intensity;
uniform int u_mode;      // 0 sphere, 1 theta_h-theta_d slice, 2 lobe / Cartesian slice, 3 directional albedo
uniform int u_which;     // 0 original (tabulation), 1 approximation (exported GLSL)
uniform vec2 u_size;
uniform mat3 u_cam;      // world = u_cam * camera
uniform float u_theta_i;
uniform float u_phi_d;
uniform int u_env;          // 1: light by the scene's SH lighting (lat-long bf_env, rule bf_rule)
uniform sampler2D bf_env;
uniform sampler2D bf_rule;  // node k at (k, 0): (direction in the local frame, weight)
uniform int u_rule_n;
// The lighting is read at u_env_rot * (world direction): u_env_rot = R^T for
// an environment turned by R (dragging the light turns it, see the script).
uniform mat3 u_env_rot;
uniform int u_out_of_plane;  // mode 2: 1 for wo in the y-z plane (normal to the incidence plane)
uniform sampler2D bf_arule;  // mode 3: hemisphere rule, node k at (k % width, k / width): (direction, weight)
uniform int u_arule_first, u_arule_n;  // mode 3: the nodes summed by this draw
uniform int u_shape;  // mode 0: 0 unit sphere, 1 torus (ring radius 0.62, tube 0.32, axis tilted 30 deg from the view direction)
out vec4 o_color;

const float BF_TORUS_R = 0.62, BF_TORUS_T = 0.32, BF_TORUS_TILT = 0.52359878;
// Camera frame -> torus frame (axis z): a rotation by the tilt about x.
vec3 bf_to_torus(vec3 p) { float c = cos(BF_TORUS_TILT), s = sin(BF_TORUS_TILT); return vec3(p.x, c * p.y + s * p.z, -s * p.y + c * p.z); }
vec3 bf_from_torus(vec3 p) { float c = cos(BF_TORUS_TILT), s = sin(BF_TORUS_TILT); return vec3(p.x, c * p.y - s * p.z, s * p.y + c * p.z); }
float bf_torus_sdf(vec3 q) { return length(vec2(length(q.xy) - BF_TORUS_R, q.z)) - BF_TORUS_T; }
// The orthographic ray through (px, py) towards -z (camera frame): the first
// hit on the torus by sphere tracing (the SDF is exact, so steps never pass
// the surface), then the surface point and its normal; false on a miss.
bool bf_torus_hit(float px, float py, out vec3 pos, out vec3 nrm) {
  vec3 o = bf_to_torus(vec3(px, py, 2.0)), d = bf_to_torus(vec3(0.0, 0.0, -1.0));
  float t = 0.0;
  for (int k = 0; k < 200; ++k) {
    float h = bf_torus_sdf(o + t * d);
    if (h < 1e-6) break;
    t += h;
    if (t > 4.0) return false;
  }
  vec3 q = o + t * d;
  if (bf_torus_sdf(q) > 1e-4) return false;
  float rho = length(q.xy);
  vec3 core = rho > 0.0 ? vec3(q.xy * (BF_TORUS_R / rho), 0.0) : vec3(BF_TORUS_R, 0.0, 0.0);
  pos = bf_from_torus(q);
  nrm = bf_from_torus(normalize(q - core));
  return true;
}

// Bilinear lookup of the lat-long map (theta = pi (y + 1/2) / H, phi = 2 pi (x + 1/2) / W),
// wrapping in phi, clamped in theta.
vec3 bf_env_radiance(vec3 w) {
  ivec2 sz = textureSize(bf_env, 0);
  float th = acos(clamp(w.z, -1.0, 1.0));
  float ph = atan(w.y, w.x);
  if (ph < 0.0) ph += 6.28318531;
  float x = ph / 6.28318531 * float(sz.x) - 0.5, y = clamp(th / 3.14159265 * float(sz.y) - 0.5, 0.0, float(sz.y - 1));
  float fx = floor(x);
  int x0 = int(fx), y0 = min(int(y), sz.y - 2);
  float a = x - fx, b = y - float(y0);
  int xa = (x0 + sz.x) % sz.x, xb = (xa + 1) % sz.x;  // x0 >= -1
  vec3 t00 = texelFetch(bf_env, ivec2(xa, y0), 0).rgb, t10 = texelFetch(bf_env, ivec2(xb, y0), 0).rgb;
  vec3 t01 = texelFetch(bf_env, ivec2(xa, y0 + 1), 0).rgb, t11 = texelFetch(bf_env, ivec2(xb, y0 + 1), 0).rgb;
  return mix(mix(t00, t10, a), mix(t01, t11, a), b);
}

vec2 bf_orig_parabolic(vec3 w) { return w.xy / (1.0 + w.z); }
vec3 bf_orig_eval(vec3 wi, vec3 wo) {
  if (wi.z <= 0.0 || wo.z <= 0.0) return vec3(0.0);
  const int R = BF_ORIG_RES;
  float Rm = float(R - 1);
  vec2 si = clamp((bf_orig_parabolic(wi) + 1.0) * 0.5 * Rm, vec2(0.0), vec2(Rm));
  vec2 so = clamp((bf_orig_parabolic(wo) + 1.0) * 0.5 * Rm, vec2(0.0), vec2(Rm));
  ivec2 ii = min(ivec2(si), ivec2(R - 2)), io = min(ivec2(so), ivec2(R - 2));
  vec2 ai = si - vec2(ii), ao = so - vec2(io);
  vec3 acc = vec3(0.0);
  for (int a = 0; a < 4; ++a) {
    ivec2 di = ivec2(a % 2, a / 2);
    float wa = (di.x == 1 ? ai.x : 1.0 - ai.x) * (di.y == 1 ? ai.y : 1.0 - ai.y);
    ivec2 ti = ii + di;
    for (int b = 0; b < 4; ++b) {
      ivec2 dd = ivec2(b % 2, b / 2);
      float wb = (dd.x == 1 ? ao.x : 1.0 - ao.x) * (dd.y == 1 ? ao.y : 1.0 - ao.y);
      ivec2 to = io + dd;
      acc += wa * wb * texelFetch(bf_orig, ivec2(to.y * R + to.x, ti.y * R + ti.x), 0).rgb;
    }
  }
  return acc;
}
// Isotropic originals: MERL-style (theta_h, theta_d, phi_d) table, nodes at
// theta_h = (i/(NH-1))^2 pi/2, theta_d = j/(ND-1) pi/2, phi_d = k/(NP-1) pi,
// pixel (k + NP j, i); read trilinearly, phi_d folded into [0, pi].
vec3 bf_orig_iso(vec3 wi, vec3 wo) {
  if (wi.z <= 0.0 || wo.z <= 0.0) return vec3(0.0);
  const float HP = 1.57079633;
  vec3 h = normalize(wi + wo);
  float th = acos(clamp(h.z, -1.0, 1.0));
  float ph = (h.x == 0.0 && h.y == 0.0) ? 0.0 : atan(h.y, h.x);
  vec3 d = vec3(cos(ph) * wi.x + sin(ph) * wi.y, -sin(ph) * wi.x + cos(ph) * wi.y, wi.z);
  d = vec3(cos(th) * d.x - sin(th) * d.z, d.y, sin(th) * d.x + cos(th) * d.z);
  float td = acos(clamp(d.z, -1.0, 1.0));
  float pd = (d.x == 0.0 && d.y == 0.0) ? 0.0 : atan(d.y, d.x);
  if (pd < 0.0) pd += 2.0 * HP;
  vec3 c = vec3(sqrt(clamp(th / HP, 0.0, 1.0)) * float(BF_ORIG_NH - 1), clamp(td / HP, 0.0, 1.0) * float(BF_ORIG_ND - 1),
                clamp(pd / (2.0 * HP), 0.0, 1.0) * float(BF_ORIG_NP - 1));
  ivec3 i0 = min(ivec3(c), ivec3(BF_ORIG_NH - 2, BF_ORIG_ND - 2, BF_ORIG_NP - 2));
  vec3 a = c - vec3(i0);
  vec3 acc = vec3(0.0);
  for (int q = 0; q < 8; ++q) {
    ivec3 o = ivec3(q % 2, (q / 2) % 2, q / 4);
    float w = (o.x == 1 ? a.x : 1.0 - a.x) * (o.y == 1 ? a.y : 1.0 - a.y) * (o.z == 1 ? a.z : 1.0 - a.z);
    ivec3 t = i0 + o;
    acc += w * texelFetch(bf_orig, ivec2(t.z + BF_ORIG_NP * t.y, t.x), 0).rgb;
  }
  return acc;
}
vec3 bf_eval(vec3 wi, vec3 wo) {
  if (u_which == 1) return brdf_factor_eval(wi, wo);
  return BF_ORIG_KIND == 1 ? bf_orig_iso(wi, wo) : bf_orig_eval(wi, wo);
}

void main() {
  vec2 f = gl_FragCoord.xy;
  // Pixel (x, y), y = 0 at the top, as the CPU render (docs/design.md §5.4).
  float px = -1.0 + 2.0 * f.x / u_size.x;
  float py = 1.0 - 2.0 * (u_size.y - f.y) / u_size.y;
  if (u_mode == 0) {
    // The surface point P and normal n in the world (the unit sphere: P = n).
    vec3 n, P;
    if (u_shape == 1) {
      vec3 pc, nc;
      if (!bf_torus_hit(px, py, pc, nc)) { o_color = vec4(0.0); return; }
      n = u_cam * nc;
      P = u_cam * pc;
    } else {
      float rr = px * px + py * py;
      if (rr >= 1.0) { o_color = vec4(0.0); return; }
      n = u_cam * vec3(px, py, sqrt(1.0 - rr));
      P = n;
    }
    vec3 wo_w = u_cam * vec3(0.0, 0.0, 1.0);
    vec3 t = vec3(1.0, 0.0, 0.0) - n.x * n;
    if (length(t) < 1e-9) t = vec3(0.0, 1.0, 0.0) - n.y * n;
    t = normalize(t);
    vec3 b = cross(n, t);
    vec3 tl = u_light - P;
    float d2 = dot(tl, tl);
    vec3 wiw = tl / sqrt(d2);
    float ci = dot(wiw, n);
    vec3 wi = vec3(dot(wiw, t), dot(wiw, b), dot(wiw, n));
    vec3 wo = vec3(dot(wo_w, t), dot(wo_w, b), dot(wo_w, n));
    vec3 L = vec3(0.0);
    if (u_env == 1) {
      if (wo.z > 0.0) {
        vec3 won = normalize(wo);
        for (int k = 0; k < u_rule_n; ++k) {
          vec4 node = texelFetch(bf_rule, ivec2(k, 0), 0);
          vec3 sw = node.x * t + node.y * b + node.z * n;
          L += node.w * node.z * bf_env_radiance(u_env_rot * sw) * bf_eval(node.xyz, won);
        }
      }
    } else if (ci > 0.0 && wo.z > 0.0) {
      L = u_intensity * bf_eval(normalize(wi), normalize(wo)) * ci / d2;
    }
    o_color = vec4(L, 1.0);
  } else if (u_mode == 1) {
    // BRDF Explorer's image slice: theta_h along x, theta_d along y (up), phi_d fixed,
    // phi_h = 0; wi = R_y(theta_h) d, wo = 2 (wi.h) h - wi.
    float th = 0.5 * 3.14159265 * (f.x / u_size.x), td = 0.5 * 3.14159265 * (f.y / u_size.y);
    vec3 h = vec3(sin(th), 0.0, cos(th));
    vec3 d = vec3(sin(td) * cos(u_phi_d), sin(td) * sin(u_phi_d), cos(td));
    vec3 wi = vec3(cos(th) * d.x + sin(th) * d.z, d.y, -sin(th) * d.x + cos(th) * d.z);
    vec3 wo = 2.0 * dot(wi, h) * h - wi;
    o_color = vec4(bf_eval(normalize(wi), normalize(wo)), 1.0);
  } else if (u_mode == 2) {
    // Lobe: wi at theta_i in the x-z plane (phi = 0), wo at theta_o in
    // [-90, 90] degrees along x (negative: the phi = 180 side), or along y
    // (out of the incidence plane: phi = 90, negative phi = 270).
    float to = -0.5 * 3.14159265 + 3.14159265 * (f.x / u_size.x);
    vec3 wi = vec3(sin(u_theta_i), 0.0, cos(u_theta_i));
    vec3 wo = u_out_of_plane == 1 ? vec3(0.0, sin(to), cos(to)) : vec3(sin(to), 0.0, cos(to));
    o_color = vec4(bf_eval(wi, wo), 1.0);
  } else {
    // Directional albedo a(wo) = integral of f(wi, wo) cos theta_i over the
    // hemisphere by the rule bf_arule, wo at theta_o = 90 deg (x + 1/2) / width
    // in the x-z plane (phi_o = 0).
    float to = 0.5 * 3.14159265 * (f.x / u_size.x);
    vec3 wo = vec3(sin(to), 0.0, cos(to));
    vec3 a = vec3(0.0);
    int rw = textureSize(bf_arule, 0).x;
    for (int k = u_arule_first; k < u_arule_first + u_arule_n; ++k) {
      vec4 node = texelFetch(bf_arule, ivec2(k % rw, k / rw), 0);
      a += node.w * node.z * bf_eval(node.xyz, wo);
    }
    o_color = vec4(a, 1.0);
  }
}
