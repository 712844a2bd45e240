#version 450
#include "map_vert.glsl"
