#version 450
#include "surface_frag.glsl"
