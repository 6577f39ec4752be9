#pragma once
/// @file
/// Choosing the LCM URL of a process.

#include <string>

namespace bookgrasp {

/// The project's default bus: loopback multicast, never leaving the host
/// (ttl=0), with a receive buffer large enough for images.
inline constexpr const char* kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304";
/// Receive buffer every udpm subscriber asks for, in bytes.
inline constexpr int kImageSafeRecvBuf = 4194304;

/// Picks the URL: `explicit_url` if not empty, else `config_url` if not empty,
/// else $LCM_DEFAULT_URL, else kDefaultLcmUrl. A udpm URL without a
/// recv_buf_size gets kImageSafeRecvBuf added, so images are not dropped.
std::string resolve_lcm_url(const std::string& explicit_url, const std::string& config_url);

/// Adds recv_buf_size to a udpm URL that has none; other URLs are returned as they are.
std::string make_image_safe(const std::string& url);

}  // namespace bookgrasp
