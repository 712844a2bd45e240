#version 450
#define TRIMMED
#include "map_vert.glsl"
