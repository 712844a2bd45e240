#version 450
#include "flat_frag.glsl"
