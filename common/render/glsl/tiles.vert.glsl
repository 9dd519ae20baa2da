// The tiles a pass covers, as triangles already in NDC (two per tile). Built with
// "#version 450 core" first.
layout(location = 0) in vec2 position;
void main() { gl_Position = vec4(position, 0.0, 1.0); }
