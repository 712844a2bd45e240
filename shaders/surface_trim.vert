#version 450
#define TRIMMED
#include "surface_vert.glsl"
