#version 450
// VK_KHR_shader_draw_parameters: BaseVertex, BaseInstance and DrawIndex into a flat color, in 1/255 steps (BaseVertex
// offset by 8 so that a negative vertexOffset shows).
#extension GL_ARB_shader_draw_parameters : require
layout(location = 0) in vec2 inPos;
layout(location = 0) out vec4 vColor;
void main() {
  gl_Position = vec4(inPos, 0.0, 1.0);
  vColor = vec4(float(gl_BaseVertexARB + 8) / 255.0, float(gl_BaseInstanceARB) / 255.0, float(gl_DrawIDARB) / 255.0,
                1.0);
}
