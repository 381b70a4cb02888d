// GLSL compile/link with readable errors.
#include "liveset/render/shader_program.hpp"

#include <glm/gtc/type_ptr.hpp>
#include <stdexcept>
#include <utility>
#include <vector>

namespace liveset::render {

namespace {

std::string one_line(std::string s) {
    for (char& c : s)
        if (c == '\n' || c == '\r') c = ' ';
    while (!s.empty() && s.back() == ' ') s.pop_back();
    return s;
}

GLuint compile(GLenum kind, const char* source) {
    const GLuint s = glCreateShader(kind);
    glShaderSource(s, 1, &source, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        GLint n = 0;
        glGetShaderiv(s, GL_INFO_LOG_LENGTH, &n);
        std::vector<char> log(static_cast<std::size_t>(std::max(n, 1)));
        glGetShaderInfoLog(s, n, nullptr, log.data());
        glDeleteShader(s);
        throw std::runtime_error(std::string(kind == GL_VERTEX_SHADER ? "vertex" : "fragment") +
                                 " shader does not compile: " + one_line(log.data()));
    }
    return s;
}

}  // namespace

ShaderProgram::ShaderProgram(const char* vertex_source, const char* fragment_source) {
    const GLuint vs = compile(GL_VERTEX_SHADER, vertex_source);
    GLuint fs = 0;
    try {
        fs = compile(GL_FRAGMENT_SHADER, fragment_source);
    } catch (...) {
        glDeleteShader(vs);
        throw;
    }
    id_ = glCreateProgram();
    glAttachShader(id_, vs);
    glAttachShader(id_, fs);
    glLinkProgram(id_);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(id_, GL_LINK_STATUS, &ok);
    if (!ok) {
        GLint n = 0;
        glGetProgramiv(id_, GL_INFO_LOG_LENGTH, &n);
        std::vector<char> log(static_cast<std::size_t>(std::max(n, 1)));
        glGetProgramInfoLog(id_, n, nullptr, log.data());
        glDeleteProgram(id_);
        id_ = 0;
        throw std::runtime_error("shader program does not link: " + one_line(log.data()));
    }
}

ShaderProgram::~ShaderProgram() {
    if (id_) glDeleteProgram(id_);
}

ShaderProgram::ShaderProgram(ShaderProgram&& other) noexcept { *this = std::move(other); }

ShaderProgram& ShaderProgram::operator=(ShaderProgram&& other) noexcept {
    if (this != &other) {
        if (id_) glDeleteProgram(id_);
        id_ = std::exchange(other.id_, 0);
        locations_ = std::move(other.locations_);
    }
    return *this;
}

GLint ShaderProgram::location(const char* name) {
    const auto it = locations_.find(name);
    if (it != locations_.end()) return it->second;
    const GLint loc = glGetUniformLocation(id_, name);
    locations_.emplace(name, loc);
    return loc;
}

void ShaderProgram::set(const char* name, const glm::mat4& m) { glUniformMatrix4fv(location(name), 1, GL_FALSE, glm::value_ptr(m)); }
void ShaderProgram::set(const char* name, const glm::mat3& m) { glUniformMatrix3fv(location(name), 1, GL_FALSE, glm::value_ptr(m)); }
void ShaderProgram::set(const char* name, const glm::vec4& v) { glUniform4fv(location(name), 1, glm::value_ptr(v)); }
void ShaderProgram::set(const char* name, const glm::vec3& v) { glUniform3fv(location(name), 1, glm::value_ptr(v)); }
void ShaderProgram::set(const char* name, const glm::vec2& v) { glUniform2fv(location(name), 1, glm::value_ptr(v)); }
void ShaderProgram::set(const char* name, float v) { glUniform1f(location(name), v); }
void ShaderProgram::set(const char* name, int v) { glUniform1i(location(name), v); }

}  // namespace liveset::render
