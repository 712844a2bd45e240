#version 450
#include "surface_vert.glsl"
