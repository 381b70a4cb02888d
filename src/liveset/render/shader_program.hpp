// A linked GLSL 3.30 program with cached uniform locations; compile and link errors become one-line
// std::runtime_error messages carrying the driver's log.
#pragma once

#include <epoxy/gl.h>

#include <glm/glm.hpp>
#include <string>
#include <unordered_map>

namespace liveset::render {

class ShaderProgram {
public:
    ShaderProgram() = default;
    ShaderProgram(const char* vertex_source, const char* fragment_source);
    ~ShaderProgram();
    ShaderProgram(ShaderProgram&& other) noexcept;
    ShaderProgram& operator=(ShaderProgram&& other) noexcept;
    ShaderProgram(const ShaderProgram&) = delete;
    ShaderProgram& operator=(const ShaderProgram&) = delete;

    void use() const { glUseProgram(id_); }
    GLuint id() const { return id_; }
    // Setters for the program in use (unknown names are ignored, as GLSL optimises them away).
    void set(const char* name, const glm::mat4& m);
    void set(const char* name, const glm::mat3& m);
    void set(const char* name, const glm::vec4& v);
    void set(const char* name, const glm::vec3& v);
    void set(const char* name, const glm::vec2& v);
    void set(const char* name, float v);
    void set(const char* name, int v);

private:
    GLint location(const char* name);
    GLuint id_ = 0;
    std::unordered_map<std::string, GLint> locations_;
};

}  // namespace liveset::render
