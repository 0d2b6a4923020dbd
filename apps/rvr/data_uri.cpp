// A file as a data URI (see data_uri.h).
#include "data_uri.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "base64.h"

namespace rvr::report {
namespace {

std::string mime_type(const std::string& file) {
  std::string ext = std::filesystem::path(file).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".png") return "image/png";
  if (ext == ".jpg" || ext == ".jpeg") return "image/jpeg";
  if (ext == ".gif") return "image/gif";
  if (ext == ".webp") return "image/webp";
  if (ext == ".bmp") return "image/bmp";
  return "application/octet-stream";
}

}  // namespace

Expected<std::string> data_uri(const std::string& out_dir, const std::string& file) {
  std::string path = (std::filesystem::path(out_dir) / file).string();
  std::ifstream in(path, std::ios::binary);
  if (!in) return internal_error("cannot read '" + path + "': no such file or not readable");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return internal_error("cannot read '" + path + "': read failed");
  return "data:" + mime_type(file) + ";base64," + base64(bytes);
}

}  // namespace rvr::report
