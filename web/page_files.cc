#include "page_files.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace snapthread::web {

namespace fs = std::filesystem;

std::string ContentType(const std::string& name) {
  const std::string ext = fs::path(name).extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json" || ext == ".map") return "application/json";
  if (ext == ".png") return "image/png";
  if (ext == ".svg") return "image/svg+xml";
  return "application/octet-stream";
}

PageFiles::PageFiles(const std::string& folder) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    if (!entry.is_regular_file()) continue;
    std::ifstream in(entry.path(), std::ios::binary);
    std::ostringstream content;
    content << in.rdbuf();
    const std::string name = entry.path().filename().string();
    files_[name] = {content.str(), ContentType(name)};
  }
  if (ec) throw std::runtime_error("cannot read the page folder " + folder + ": " + ec.message());
  if (files_.count("index.html") == 0) {
    throw std::runtime_error("no index.html in the page folder " + folder +
                             " (the page is built with the snapthread-web target)");
  }
}

const PageFile* PageFiles::Find(const std::string& path) const {
  std::string name = path;
  if (name.empty() || name == "/") name = "/index.html";
  if (name[0] != '/' || name.find('/', 1) != std::string::npos) return nullptr;
  const auto it = files_.find(name.substr(1));
  return it == files_.end() ? nullptr : &it->second;
}

}  // namespace snapthread::web
