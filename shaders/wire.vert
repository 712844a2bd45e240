#version 450
#include "wire_vert.glsl"
