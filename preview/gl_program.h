// GL shader programs of the preview renderer: compiling, linking, uniform locations and the
// driver's extensions. Needs a current GL context with glad loaded. Compile and link errors throw
// Failure with the driver's log.
#pragma once

#include <glad/gl.h>

#include <string>

namespace lumislab {

// A program of a vertex and a fragment shader, or of one compute shader.
GLuint LinkProgram(const std::string& vertex, const std::string& fragment);
GLuint LinkComputeProgram(const std::string& compute);

// The location of a uniform (-1 where the program has none: glUniform* then does nothing).
inline GLint Loc(GLuint program, const char* name) { return glGetUniformLocation(program, name); }

// `source` with `defines` (whole lines) inserted after its first line, the #version line.
std::string WithDefines(const std::string& source, const std::string& defines);

// Whether the current context has the extension `name`.
bool HasExtension(const char* name);

}  // namespace lumislab
