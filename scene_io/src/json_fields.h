// Typed access to the fields of a scene file's JSON, with validation: each function returns the
// value or fails with the field's path and what is wrong. Private to scene_io/src.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "scene_json_errors.h"

namespace rvr::scene_load {

const json* find(const json& obj, const char* key);
const json& require(const json& obj, const std::string& path, const char* key,
                    const std::string& hint = {});
void check_object(const json& v, const std::string& path);
// Fails on a key not in `allowed`, suggesting the likely one.
void check_keys(const json& obj, const std::string& path, const std::vector<std::string>& allowed,
                const std::string& context = {});
double number(const json& v, const std::string& path);
// A number that must also fit a 32-bit float (the model stores floats).
float real(const json& v, const std::string& path);

enum class Bound { Open, Closed };

float real_at_least(const json& v, const std::string& path, double lo, Bound b);
float real_in_unit(const json& v, const std::string& path);
int integer(const json& v, const std::string& path, int64_t lo, int64_t hi,
            const std::string& note = {});
bool boolean(const json& v, const std::string& path);
const std::string& string(const json& v, const std::string& path);
glm::vec3 vec3(const json& v, const std::string& path, const char* what = "3 numbers");
glm::vec3 colour(const json& v, const std::string& path);
std::string vec_text(const glm::vec3& v);

}  // namespace rvr::scene_load
