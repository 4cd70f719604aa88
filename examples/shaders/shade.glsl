// Direct lighting with a shadow ray (a second trace), ambient light, and one mirror bounce (recursion depth 3 at
// most: camera ray, reflected ray, shadow ray).
layout(location = 0) rayPayloadInEXT RadiancePayload payload;
layout(location = 1) rayPayloadEXT float lit;
layout(location = 2) rayPayloadEXT RadiancePayload bounce;

vec3 shade(vec3 p, vec3 n, Material m) {
  vec3 l = kLight - p;
  float dist = length(l);
  l /= dist;
  if (dot(n, gl_WorldRayDirectionEXT) > 0.0) n = -n;  // seen from behind
  float ndotl = max(dot(n, l), 0.0);
  lit = 0.0;
  if (ndotl > 0.0) {
    // Any opaque hit (or alpha-tested one that its any-hit shader keeps) shadows: terminate on the first hit, no
    // closest-hit shader; miss shader 1 sets lit = 1.
    traceRayEXT(scene, gl_RayFlagsTerminateOnFirstHitEXT | gl_RayFlagsSkipClosestHitShaderEXT, 0xff, 0, 1, 1,
                p + n * 1e-3, 0.0, l, dist - 1e-3, 1);
  }
  vec3 color = m.albedo.rgb * (0.12 + 0.88 * lit * ndotl * kLightColor / (0.25 + 0.35 * dist * dist));
  if (m.albedo.a > 0.0 && payload.depth < 1u) {
    bounce.color = vec3(0.0);
    bounce.depth = payload.depth + 1u;
    vec3 r = reflect(gl_WorldRayDirectionEXT, n);
    traceRayEXT(scene, gl_RayFlagsNoneEXT, 0xff, 0, 1, 0, p + n * 1e-3, 0.0, r, 100.0, 2);
    color = mix(color, bounce.color, m.albedo.a);
  }
  return color;
}
