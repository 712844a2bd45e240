#version 450
#define TRIMMED
#include "wire_vert.glsl"
