#version 450
#define TRIMMED
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference_uvec2 : require
#include "surface_vert.glsl"
