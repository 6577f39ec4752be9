#include "common/lcm_url.h"

#include <cstdlib>

namespace bookgrasp {

std::string make_image_safe(const std::string& url) {
  if (url.rfind("udpm://", 0) != 0) return url;
  if (url.find("recv_buf_size=") != std::string::npos) return url;
  const char sep = url.find('?') == std::string::npos ? '?' : '&';
  return url + sep + "recv_buf_size=" + std::to_string(kImageSafeRecvBuf);
}

std::string resolve_lcm_url(const std::string& explicit_url, const std::string& config_url) {
  if (!explicit_url.empty()) return make_image_safe(explicit_url);
  if (!config_url.empty()) return make_image_safe(config_url);
  const char* env = std::getenv("LCM_DEFAULT_URL");
  if (env && *env) return make_image_safe(env);
  return kDefaultLcmUrl;
}

}  // namespace bookgrasp
