#include "common/image_conversion.h"

#include <cmath>
#include <cstring>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace bookgrasp {

int bytes_per_pixel(int8_t f) {
  switch (f) {
    case image_t::GRAY8: return 1;
    case image_t::RGB8: return 3;
    case image_t::DEPTH_F32: return 4;
    case image_t::DEPTH_U16: return 2;
    case image_t::DISPARITY_F32: return 4;
    case image_t::LABEL_I32: return 4;
    case image_t::PNG:
    case image_t::JPEG: return 0;
    default: return -1;
  }
}

std::string pixel_format_name(int8_t f) {
  switch (f) {
    case image_t::GRAY8: return "GRAY8";
    case image_t::RGB8: return "RGB8";
    case image_t::DEPTH_F32: return "DEPTH_F32";
    case image_t::DEPTH_U16: return "DEPTH_U16";
    case image_t::DISPARITY_F32: return "DISPARITY_F32";
    case image_t::PNG: return "PNG";
    case image_t::JPEG: return "JPEG";
    case image_t::LABEL_I32: return "LABEL_I32";
    default: return "unknown(" + std::to_string(static_cast<int>(f)) + ")";
  }
}

namespace {

int cv_type_of(int8_t f) {
  switch (f) {
    case image_t::GRAY8: return CV_8UC1;
    case image_t::RGB8: return CV_8UC3;
    case image_t::DEPTH_F32: return CV_32FC1;
    case image_t::DEPTH_U16: return CV_16UC1;
    case image_t::DISPARITY_F32: return CV_32FC1;
    case image_t::LABEL_I32: return CV_32SC1;
    default: return -1;
  }
}

std::string describe(const image_t& m) {
  return "image '" + m.frame + "' " + std::to_string(m.width) + "x" + std::to_string(m.height) + " " +
         pixel_format_name(m.pixel_format);
}

void check_size(const image_t& m) {
  if (m.width <= 0 || m.height <= 0 || m.width > kMaxImageSide || m.height > kMaxImageSide)
    throw ImageError(describe(m) + ": width and height must be in 1.." + std::to_string(kMaxImageSide));
  if (m.size != static_cast<int32_t>(m.data.size()))
    throw ImageError(describe(m) + ": size field " + std::to_string(m.size) + " != data length " +
                     std::to_string(m.data.size()));
}

}  // namespace

cv::Mat image_to_mat(const image_t& m) {
  check_size(m);
  if (m.pixel_format == image_t::PNG || m.pixel_format == image_t::JPEG) {
    if (m.data.empty()) throw ImageError(describe(m) + ": empty encoded data");
    cv::Mat buf(1, static_cast<int>(m.data.size()), CV_8UC1, const_cast<uint8_t*>(m.data.data()));
    cv::Mat img = cv::imdecode(buf, cv::IMREAD_UNCHANGED);
    if (img.empty()) throw ImageError(describe(m) + ": the data does not decode as " + pixel_format_name(m.pixel_format));
    if (img.cols != m.width || img.rows != m.height)
      throw ImageError(describe(m) + ": decoded size " + std::to_string(img.cols) + "x" + std::to_string(img.rows) +
                       " differs from the header");
    if (img.channels() == 3) cv::cvtColor(img, img, cv::COLOR_BGR2RGB);
    else if (img.channels() == 4) cv::cvtColor(img, img, cv::COLOR_BGRA2RGB);
    return img;
  }
  const int type = cv_type_of(m.pixel_format);
  if (type < 0) throw ImageError(describe(m) + ": unknown pixel format");
  const int bpp = bytes_per_pixel(m.pixel_format);
  const int64_t min_stride = static_cast<int64_t>(m.width) * bpp;
  if (m.row_stride < min_stride)
    throw ImageError(describe(m) + ": row_stride " + std::to_string(m.row_stride) + " < width * " +
                     std::to_string(bpp) + " bytes");
  const int64_t need = static_cast<int64_t>(m.row_stride) * m.height;
  if (static_cast<int64_t>(m.data.size()) < need)
    throw ImageError(describe(m) + ": data has " + std::to_string(m.data.size()) + " bytes, needs row_stride * height = " +
                     std::to_string(need));
  cv::Mat view(m.height, m.width, type, const_cast<uint8_t*>(m.data.data()), static_cast<size_t>(m.row_stride));
  return view.clone();
}

cv::Mat depth_to_metres(const image_t& m) {
  cv::Mat raw = image_to_mat(m);
  cv::Mat out;
  if (m.pixel_format == image_t::DEPTH_F32) {
    out = raw;
  } else if (m.pixel_format == image_t::DEPTH_U16 || (m.pixel_format == image_t::PNG && raw.type() == CV_16UC1)) {
    if (!(m.depth_scale > 0) || !std::isfinite(m.depth_scale))
      throw ImageError(describe(m) + ": 16-bit depth needs depth_scale > 0 (metres per count)");
    raw.convertTo(out, CV_32FC1, m.depth_scale);
    out.setTo(std::numeric_limits<float>::quiet_NaN(), raw == 0);
  } else {
    throw ImageError(describe(m) + ": not a depth image (DEPTH_F32, DEPTH_U16 or 16-bit PNG expected)");
  }
  return out;
}

image_t mat_to_image(const cv::Mat& mat, int8_t f, int64_t utime, const std::string& frame, float depth_scale) {
  const int type = cv_type_of(f);
  if (type < 0) throw ImageError("mat_to_image: " + pixel_format_name(f) + " is not a raw pixel format");
  if (mat.type() != type)
    throw ImageError("mat_to_image: cv::Mat type " + std::to_string(mat.type()) + " does not match " +
                     pixel_format_name(f));
  if (mat.empty() || mat.cols > kMaxImageSide || mat.rows > kMaxImageSide)
    throw ImageError("mat_to_image: image must be 1.." + std::to_string(kMaxImageSide) + " pixels per side");
  image_t m;
  m.utime = utime;
  m.frame = frame;
  m.width = mat.cols;
  m.height = mat.rows;
  m.pixel_format = f;
  m.depth_scale = depth_scale;
  m.row_stride = mat.cols * bytes_per_pixel(f);
  m.data.resize(static_cast<size_t>(m.row_stride) * mat.rows);
  for (int r = 0; r < mat.rows; ++r) std::memcpy(&m.data[static_cast<size_t>(r) * m.row_stride], mat.ptr(r), m.row_stride);
  m.size = static_cast<int32_t>(m.data.size());
  return m;
}

namespace {
image_t encode(const cv::Mat& mat, int8_t f, const std::string& ext, const std::vector<int>& params, int64_t utime,
               const std::string& frame, float depth_scale) {
  if (mat.empty()) throw ImageError("encode " + ext + ": empty image");
  // A fresh Mat for the conversion: cvtColor into a header copy would write into the caller's pixels.
  cv::Mat bgr;
  if (mat.type() == CV_8UC3) cv::cvtColor(mat, bgr, cv::COLOR_RGB2BGR);
  else bgr = mat;
  if (mat.type() != CV_8UC3 && mat.type() != CV_8UC1 && !(mat.type() == CV_16UC1 && ext == ".png"))
    throw ImageError("encode " + ext + ": unsupported cv::Mat type " + std::to_string(mat.type()));
  std::vector<uint8_t> buf;
  if (!cv::imencode(ext, bgr, buf, params)) throw ImageError("encode " + ext + ": OpenCV failed");
  image_t m;
  m.utime = utime;
  m.frame = frame;
  m.width = mat.cols;
  m.height = mat.rows;
  m.row_stride = 0;
  m.pixel_format = f;
  m.depth_scale = depth_scale;
  m.data = std::move(buf);
  m.size = static_cast<int32_t>(m.data.size());
  return m;
}
}  // namespace

image_t encode_png(const cv::Mat& mat, int64_t utime, const std::string& frame, float depth_scale) {
  return encode(mat, image_t::PNG, ".png", {cv::IMWRITE_PNG_COMPRESSION, 1}, utime, frame, depth_scale);
}

image_t encode_jpeg(const cv::Mat& mat, int64_t utime, const std::string& frame, int quality) {
  if (quality < 1 || quality > 100) throw ImageError("encode_jpeg: quality must be 1..100");
  return encode(mat, image_t::JPEG, ".jpg", {cv::IMWRITE_JPEG_QUALITY, quality}, utime, frame, 0.0f);
}

image_t encode_image(const cv::Mat& mat, const std::string& encoding, int64_t utime, const std::string& frame) {
  if (encoding == "png") return encode_png(mat, utime, frame);
  if (encoding == "jpeg") return encode_jpeg(mat, utime, frame, 90);
  if (encoding == "raw") return mat_to_image(mat, mat.channels() == 3 ? image_t::RGB8 : image_t::GRAY8, utime, frame);
  throw ImageError("unknown image encoding '" + encoding + "' (raw, png or jpeg)");
}

cv::Mat to_rgb_copy(const cv::Mat& image) {
  cv::Mat rgb;
  if (image.channels() == 1)
    cv::cvtColor(image, rgb, cv::COLOR_GRAY2RGB);
  else
    rgb = image.clone();
  return rgb;
}

void write_png(const std::string& path, const cv::Mat& mat) {
  cv::Mat out;
  if (mat.type() == CV_8UC3) cv::cvtColor(mat, out, cv::COLOR_RGB2BGR);
  else out = mat;
  if (mat.type() != CV_8UC3 && mat.type() != CV_8UC1 && mat.type() != CV_16UC1)
    throw ImageError("write_png " + path + ": unsupported cv::Mat type " + std::to_string(mat.type()));
  if (!cv::imwrite(path, out)) throw ImageError("write_png: cannot write '" + path + "'");
}

}  // namespace bookgrasp
