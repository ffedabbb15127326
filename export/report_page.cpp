#include "export/report_page.h"

#include <nlohmann/json.hpp>

namespace lacuna {
namespace {

// JSON inside a <script> element: "</" could close it, so it is written "<\/" (the same string).
std::string script_json(const nlohmann::json& j) {
  const std::string text = j.dump();
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size(); ++i) {
    out += text[i];
    if (text[i] == '<' && i + 1 < text.size() && text[i + 1] == '/') out += '\\';
  }
  return out;
}

std::string html_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

constexpr const char* kStyle = R"(
body { font: 14px/1.45 system-ui, sans-serif; margin: 0 auto; max-width: 1200px; padding: 1em 2em; color: #1d2330; }
h1 { margin-bottom: 0.2em; } h2 { margin-top: 1.6em; border-bottom: 1px solid #d5d9e0; }
.valid { color: #1b7a3a; } .invalid { color: #b3261e; }
table { border-collapse: collapse; margin: 0.5em 0; } th, td { padding: 3px 10px; border-bottom: 1px solid #e4e7ec; text-align: left; }
td code { font-size: 12px; word-break: break-all; }
.bar { background: #8fa9c4; height: 10px; min-width: 2px; }
.toolbar { display: flex; flex-wrap: wrap; gap: 12px; align-items: center; margin: 0.5em 0; }
#viewer { width: 100%; height: 560px; border: 1px solid #d5d9e0; }
#viewer canvas { width: 100%; height: 100%; display: block; }
.pictures figure { display: inline-block; vertical-align: top; margin: 0 1.5em 1em 0; }
.pictures img { width: 540px; max-width: 100%; height: auto; border: 1px solid #d5d9e0; background: #fff; }
.pictures figcaption { max-width: 540px; }
.track { width: 320px; }
)";

}  // namespace

std::string base64(const std::string& bytes) {
  static constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const uint32_t v = uint32_t(uint8_t(bytes[i])) << 16 | uint32_t(uint8_t(bytes[i + 1])) << 8 | uint8_t(bytes[i + 2]);
    out += kDigits[v >> 18];
    out += kDigits[(v >> 12) & 63];
    out += kDigits[(v >> 6) & 63];
    out += kDigits[v & 63];
  }
  if (i < bytes.size()) {
    uint32_t v = uint32_t(uint8_t(bytes[i])) << 16;
    if (i + 1 < bytes.size()) v |= uint32_t(uint8_t(bytes[i + 1])) << 8;
    out += kDigits[v >> 18];
    out += kDigits[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kDigits[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string report_page_html(const nlohmann::json& report, const ReportPage& page) {
  nlohmann::json data = {{"build_direction", {page.build_direction.x, page.build_direction.y, page.build_direction.z}},
                         {"meshes", nlohmann::json::array()},
                         {"skipped", nlohmann::json::array()},
                         {"pictures", nlohmann::json::array()}};
  for (const PageMesh& m : page.meshes) {
    nlohmann::json markers = nlohmann::json::array();
    for (const PageMarker& k : m.markers)
      markers.push_back({{"kind", k.kind}, {"location", {k.location_mm.x, k.location_mm.y, k.location_mm.z}}});
    data["meshes"].push_back({{"object", m.object}, {"outputs", m.outputs}, {"markers", markers}, {"draco", base64(m.draco)}});
  }
  for (const auto& [object, why] : page.skipped) data["skipped"].push_back({{"object", object}, {"reason", why}});
  for (const PagePicture& p : page.pictures)
    data["pictures"].push_back({{"caption", p.caption}, {"type", p.type}, {"data", base64(p.data)}});

  const std::string name = report.value("name", std::string("Lacuna run"));
  std::string html;
  html += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  // Nothing may leave the page: no fetch, no image or font from elsewhere. The viewer compiles
  // Draco's decoder from the WebAssembly inside the script ('wasm-unsafe-eval').
  html += "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; script-src 'unsafe-inline' "
          "'wasm-unsafe-eval'; style-src 'unsafe-inline'; img-src data:\">\n";
  html += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  html += "<title>" + html_escape(name) + ": Lacuna report</title>\n<style>" + std::string(kStyle) + "</style>\n";
  html += "</head>\n<body>\n<main id=\"lacuna\"></main>\n";
  html += "<noscript>This report draws its tables and 3D views with JavaScript; report.json holds the same figures.</noscript>\n";
  html += "<pre id=\"lacuna-page-state\" hidden></pre>\n";
  html += "<script type=\"application/json\" id=\"lacuna-report\">" + script_json(report) + "</script>\n";
  html += "<script type=\"application/json\" id=\"lacuna-page-data\">" + script_json(data) + "</script>\n";
  html += "<script>";
  html += viewer_script();
  html += "</script>\n</body>\n</html>\n";
  return html;
}

}  // namespace lacuna
