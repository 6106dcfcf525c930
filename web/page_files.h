// The page's files (web/page, bundled at build time into one folder: index.html, the
// script bundle, the style sheets), read into memory at start-up and served by name.
// Only the files of that folder exist for a request: no path from the client reaches the
// file system.
#pragma once

#include <map>
#include <string>

namespace snapthread::web {

struct PageFile {
  std::string content;
  std::string content_type;
};

class PageFiles {
 public:
  // Reads every regular file directly in `folder`; throws std::runtime_error when the
  // folder cannot be read or has no index.html (the page was not built).
  explicit PageFiles(const std::string& folder);

  // The file for a request path ("/" is index.html); nullptr when there is none.
  const PageFile* Find(const std::string& path) const;
  size_t size() const { return files_.size(); }

 private:
  std::map<std::string, PageFile> files_;  // by name
};

// "text/html; charset=utf-8", "text/javascript; charset=utf-8", ... by extension.
std::string ContentType(const std::string& name);

}  // namespace snapthread::web
