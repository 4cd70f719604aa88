#version 460
#extension GL_EXT_ray_tracing : require
layout(location = 0) rayPayloadInEXT vec4 payload;
layout(location = 0) callableDataEXT uint data;
void main() {
  data = gl_PrimitiveID;
  executeCallableEXT(0, 0);
  payload = vec4(float(data));
}
