#version 450
#include "map_frag.glsl"
