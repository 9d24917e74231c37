// EXR, Radiance .hdr and PNG reading and writing on OpenEXR and libpng (see image_io.h).
#include "factor/image_io.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/OpenEXRConfig.h>
#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <stdexcept>

namespace bf {

namespace fs = std::filesystem;

namespace {

// Refuses anything but an existing regular file (a FIFO or a device would
// block or never end), without saying more than that about the path.
void require_regular_file(const std::string& path, const char* what) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st))
    throw std::invalid_argument(path + ": cannot open " + what + ": file not found");
  if (!fs::is_regular_file(st))
    throw std::invalid_argument(path + ": cannot open " + what + ": expected a regular file");
}

void check_pixels(const std::string& path, long long w, long long h, long long max_pixels) {
  if (w < 1 || h < 1)
    throw std::invalid_argument(path + ": expected an image of at least 1x1 pixels, found " +
                                std::to_string(w) + "x" + std::to_string(h));
  if (w > max_pixels || h > max_pixels || w * h > max_pixels)
    throw std::invalid_argument(path + ": expected at most " + std::to_string(max_pixels) +
                                " pixels, found " + std::to_string(w) + "x" + std::to_string(h));
}

// OpenEXR checks image and tile sizes against a process-wide limit before it
// allocates anything for them; set it once to what we accept.
void limit_openexr_sizes() {
  static std::once_flag once;
  std::call_once(once, [] {
    Imf::Header::setMaxImageSize(1 << 16, 1 << 16);
    Imf::Header::setMaxTileSize(1 << 12, 1 << 12);
  });
}

}  // namespace

// ================================================================ EXR

ImageSize read_exr_size(const std::string& path) {
  require_regular_file(path, "EXR image");
  limit_openexr_sizes();
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i dw = file.header().dataWindow();
    const long long w = (long long)dw.max.x - dw.min.x + 1, h = (long long)dw.max.y - dw.min.y + 1;
    check_pixels(path, w, h, kMaxImagePixels);
    return {int(w), int(h)};
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::exception& e) {
    throw std::invalid_argument(path + ": cannot read EXR image: " + e.what());
  }
}

FloatImage read_exr(const std::string& path, long long max_pixels) {
  require_regular_file(path, "EXR image");
  limit_openexr_sizes();
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i dw = file.header().dataWindow();
    const long long w = (long long)dw.max.x - dw.min.x + 1, h = (long long)dw.max.y - dw.min.y + 1;
    if (dw.min.x != 0 || dw.min.y != 0)
      throw std::invalid_argument(path + ": expected the data window to start at (0, 0), found (" +
                                  std::to_string(dw.min.x) + ", " + std::to_string(dw.min.y) + ")");
    check_pixels(path, w, h, max_pixels);
    FloatImage img;
    img.width = int(w);
    img.height = int(h);
    const Imf::ChannelList& channels = file.header().channels();
    for (auto it = channels.begin(); it != channels.end(); ++it) img.channel_names.emplace_back(it.name());
    const size_t nch = img.channel_names.size();
    if (nch == 0) throw std::invalid_argument(path + ": expected at least one channel, found none");
    img.pixels.assign(size_t(w) * size_t(h) * nch, 0.0f);
    Imf::FrameBuffer fb;
    const size_t xs = sizeof(float) * nch, ys = xs * size_t(w);
    for (size_t c = 0; c < nch; ++c)
      fb.insert(img.channel_names[c],
                Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(img.pixels.data() + c), xs, ys));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    return img;
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::exception& e) {
    throw std::invalid_argument(path + ": cannot read EXR image: " + e.what());
  }
}

FloatImage read_exr_rgb(const std::string& path, bool allow_luminance, long long max_pixels) {
  FloatImage in = read_exr(path, max_pixels);
  const size_t n = size_t(in.width) * size_t(in.height);
  FloatImage out;
  out.width = in.width;
  out.height = in.height;
  out.channel_names = {"R", "G", "B"};
  out.pixels.resize(n * 3);
  const int nch = in.channels();
  if (allow_luminance && nch == 1) {
    for (size_t k = 0; k < n; ++k) out.pixels[3 * k] = out.pixels[3 * k + 1] = out.pixels[3 * k + 2] = in.pixels[k];
    return out;
  }
  int src[3] = {-1, -1, -1};
  for (int c = 0; c < nch; ++c)
    for (int k = 0; k < 3; ++k)
      if (in.channel_names[c] == out.channel_names[k]) src[k] = c;
  if (nch != 3 || src[0] < 0 || src[1] < 0 || src[2] < 0) {
    std::string names;
    for (const auto& s : in.channel_names) names += (names.empty() ? "" : ", ") + s;
    throw std::invalid_argument(path + ": expected 3 channels (R, G, B), found " + std::to_string(nch) +
                                (names.empty() ? "" : " (" + names + ")"));
  }
  for (size_t k = 0; k < n; ++k)
    for (int c = 0; c < 3; ++c) out.pixels[3 * k + c] = in.pixels[k * nch + src[c]];
  return out;
}

void write_exr(const std::string& path, const FloatImage& image, const std::string& comment) {
  const size_t nch = image.channel_names.size();
  if (image.width < 1 || image.height < 1 || nch == 0 ||
      image.pixels.size() != size_t(image.width) * size_t(image.height) * nch)
    throw std::runtime_error(path + ": write_exr: inconsistent image (" + std::to_string(image.width) + "x" +
                             std::to_string(image.height) + ", " + std::to_string(nch) + " channels, " +
                             std::to_string(image.pixels.size()) + " floats)");
  try {
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const auto& name : image.channel_names) header.channels().insert(name, Imf::Channel(Imf::FLOAT));
    if (!comment.empty()) Imf::addComments(header, comment);
    Imf::OutputFile file(path.c_str(), header);
    Imf::FrameBuffer fb;
    const size_t xs = sizeof(float) * nch, ys = xs * size_t(image.width);
    // OpenEXR only reads through the slices when writing.
    char* base = const_cast<char*>(reinterpret_cast<const char*>(image.pixels.data()));
    for (size_t c = 0; c < nch; ++c)
      fb.insert(image.channel_names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
    file.setFrameBuffer(fb);
    file.writePixels(image.height);
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": cannot write EXR image: " + e.what());
  }
}

// ================================================================ Radiance .hdr

namespace {

std::vector<unsigned char> slurp_bounded(const std::string& path, const char* what, uintmax_t max_bytes) {
  require_regular_file(path, what);
  std::error_code ec;
  const uintmax_t size = fs::file_size(path, ec);
  if (ec) throw std::invalid_argument(path + ": cannot open " + what + ": " + ec.message());
  if (size > max_bytes)
    throw std::invalid_argument(path + ": expected at most " + std::to_string(max_bytes) + " bytes, found " +
                                std::to_string(size));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(path + ": cannot open " + what);
  std::vector<unsigned char> bytes(size);
  in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(size));
  if (size_t(in.gcount()) != size)
    throw std::invalid_argument(path + ": expected " + std::to_string(size) + " bytes, read " +
                                std::to_string(in.gcount()));
  return bytes;
}

float rgbe_component(unsigned char m, unsigned char e) {
  return e == 0 ? 0.0f : float(std::ldexp(m + 0.5, int(e) - 136));
}

}  // namespace

FloatImage read_hdr(const std::string& path, long long max_pixels) {
  // RLE never expands a pixel beyond 4 bytes + a marker per run: bound the file by the pixel limit.
  const std::vector<unsigned char> b = slurp_bounded(path, "Radiance image", uintmax_t(max_pixels) * 5 + 65536);
  size_t pos = 0;
  auto line = [&](size_t& line_no) {
    const size_t start = pos;
    while (pos < b.size() && b[pos] != '\n') ++pos;
    if (pos >= b.size())
      throw std::invalid_argument(path + ": line " + std::to_string(line_no) + ": expected a header line, found end of file");
    std::string s(b.begin() + long(start), b.begin() + long(pos));
    ++pos;
    ++line_no;
    return s;
  };
  size_t line_no = 1;
  const std::string magic = line(line_no);
  if (magic.rfind("#?", 0) != 0)
    throw std::invalid_argument(path + ": line 1: expected \"#?RADIANCE\", found \"" + magic.substr(0, 40) + "\"");
  for (;;) {
    const std::string s = line(line_no);
    if (s.empty()) break;
    if (s.rfind("FORMAT=", 0) == 0 && s != "FORMAT=32-bit_rle_rgbe")
      throw std::invalid_argument(path + ": line " + std::to_string(line_no - 1) +
                                  ": expected FORMAT=32-bit_rle_rgbe, found " + s.substr(0, 60));
  }
  const std::string res = line(line_no);
  long long h = 0, w = 0;
  char ys = 0, xs = 0, yc = 0, xc = 0;
  if (std::sscanf(res.c_str(), "%c%c %lld %c%c %lld", &ys, &yc, &h, &xs, &xc, &w) != 6 || ys != '-' || yc != 'Y' ||
      xs != '+' || xc != 'X')
    throw std::invalid_argument(path + ": line " + std::to_string(line_no - 1) +
                                ": expected a resolution \"-Y H +X W\", found \"" + res.substr(0, 60) + "\"");
  check_pixels(path, w, h, max_pixels);
  FloatImage img;
  img.width = int(w);
  img.height = int(h);
  img.channel_names = {"R", "G", "B"};
  img.pixels.assign(size_t(w) * size_t(h) * 3, 0.0f);
  std::vector<unsigned char> scan(size_t(w) * 4);
  auto need = [&](size_t n, long long y) {
    if (b.size() - pos < n)
      throw std::invalid_argument(path + ": scanline " + std::to_string(y) + ": expected more pixel data, found end of file");
  };
  for (long long y = 0; y < h; ++y) {
    const bool rle = w >= 8 && w < 32768 && b.size() - pos >= 4 && b[pos] == 2 && b[pos + 1] == 2 && !(b[pos + 2] & 0x80);
    if (rle) {
      if (((long long)b[pos + 2] << 8 | b[pos + 3]) != w)
        throw std::invalid_argument(path + ": scanline " + std::to_string(y) + ": expected a run-length width of " +
                                    std::to_string(w) + ", found " + std::to_string(b[pos + 2] << 8 | b[pos + 3]));
      pos += 4;
      for (int c = 0; c < 4; ++c) {
        long long x = 0;
        while (x < w) {
          need(1, y);
          int count = b[pos++];
          const bool run = count > 128;
          if (run) count -= 128;
          if (count == 0 || x + count > w)
            throw std::invalid_argument(path + ": scanline " + std::to_string(y) + ": expected a run of 1.." +
                                        std::to_string(w - x) + " pixels, found " + std::to_string(count));
          need(run ? 1 : size_t(count), y);
          for (int k = 0; k < count; ++k) scan[size_t(x + k) * 4 + c] = run ? b[pos] : b[pos + k];
          pos += run ? 1 : size_t(count);
          x += count;
        }
      }
    } else {
      need(scan.size(), y);
      std::memcpy(scan.data(), b.data() + pos, scan.size());
      pos += scan.size();
    }
    for (long long x = 0; x < w; ++x) {
      const unsigned char* p = &scan[size_t(x) * 4];
      float* o = &img.pixels[(size_t(y) * size_t(w) + size_t(x)) * 3];
      for (int c = 0; c < 3; ++c) o[c] = rgbe_component(p[c], p[3]);
    }
  }
  return img;
}

void write_hdr(const std::string& path, const FloatImage& rgb) {
  if (rgb.channels() != 3 || rgb.pixels.size() != size_t(rgb.width) * size_t(rgb.height) * 3)
    throw std::runtime_error(path + ": write_hdr: expected an RGB image");
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error(path + ": cannot open for writing");
  out << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " << rgb.height << " +X " << rgb.width << "\n";
  std::vector<unsigned char> bytes(rgb.pixels.size() / 3 * 4, 0);
  for (size_t k = 0; k < rgb.pixels.size() / 3; ++k) {
    const float* p = &rgb.pixels[3 * k];
    const double v = std::max({double(p[0]), double(p[1]), double(p[2])});
    if (!(v >= 1e-32)) continue;  // zero, negative or NaN: stored as black
    int e = 0;
    const double m = std::frexp(v, &e);
    if (e + 128 > 255) throw std::runtime_error(path + ": write_hdr: value " + std::to_string(v) + " out of range");
    const double scale = m * 256.0 / v;
    for (int c = 0; c < 3; ++c) bytes[4 * k + c] = (unsigned char)std::clamp(p[c] * scale, 0.0, 255.0);
    bytes[4 * k + 3] = (unsigned char)(e + 128);
  }
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  out.close();
  if (!out) throw std::runtime_error(path + ": write failed");
}

// ================================================================ PNG

void write_png_rgb8(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb) {
  if (width < 1 || height < 1 || rgb.size() != size_t(width) * size_t(height) * 3)
    throw std::runtime_error(path + ": write_png_rgb8: expected " + std::to_string(width) + "x" +
                             std::to_string(height) + "x3 bytes, found " + std::to_string(rgb.size()));
  png_image img;
  std::memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  img.width = png_uint_32(width);
  img.height = png_uint_32(height);
  img.format = PNG_FORMAT_RGB;  // 8-bit sRGB (the simplified API writes the sRGB chunk)
  if (!png_image_write_to_file(&img, path.c_str(), 0, rgb.data(), 0, nullptr)) {
    const std::string err = img.message;
    png_image_free(&img);
    throw std::runtime_error(path + ": cannot write PNG: " + err);
  }
}

std::vector<uint8_t> read_png_rgb8(const std::string& path, int& width, int& height) {
  require_regular_file(path, "PNG image");
  png_image img;
  std::memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&img, path.c_str()))
    throw std::invalid_argument(path + ": cannot read PNG: " + std::string(img.message));
  try {
    check_pixels(path, img.width, img.height, kMaxImagePixels);
  } catch (...) {
    png_image_free(&img);
    throw;
  }
  img.format = PNG_FORMAT_RGB;
  std::vector<uint8_t> px(PNG_IMAGE_SIZE(img));
  if (!png_image_finish_read(&img, nullptr, px.data(), 0, nullptr)) {
    const std::string err = img.message;
    png_image_free(&img);
    throw std::invalid_argument(path + ": cannot read PNG: " + err);
  }
  width = int(img.width);
  height = int(img.height);
  return px;
}

std::string openexr_version() { return OPENEXR_VERSION_STRING; }
std::string libpng_version() { return PNG_LIBPNG_VER_STRING; }

}  // namespace bf
