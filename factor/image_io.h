// Image files the toolkit reads and writes: float EXR (factor textures,
// environment maps), Radiance .hdr (environment maps) and 8-bit PNG
// (previews, renders). Written on OpenEXR and libpng directly, so a process
// loads only those two libraries for images.
//
// Pixel layout everywhere: row-major, row 0 is the top row of the image (the
// first scanline in the file), x grows to the right; channels interleaved.
// Errors throw std::invalid_argument (bad or unreadable input, message starts
// with the path) or std::runtime_error (a write that failed).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace bf {

// A float image: width x height pixels of `channels` interleaved floats.
struct FloatImage {
  int width = 0;
  int height = 0;
  std::vector<std::string> channel_names;  // as stored in the file, e.g. {"R","G","B"}
  std::vector<float> pixels;               // width*height*channels, row 0 on top
  int channels() const { return int(channel_names.size()); }
};

// Largest image (pixels) any reader here accepts: 2^26 (8192 x 8192); a
// header that claims more is refused before anything is allocated.
constexpr long long kMaxImagePixels = 1LL << 26;

// The size of an OpenEXR file's data window, read from its header only
// (nothing is allocated for the pixels), so a caller can check it first.
struct ImageSize {
  int width = 0;
  int height = 0;
};
ImageSize read_exr_size(const std::string& path);

// Reads an OpenEXR file's data window (must start at (0, 0)) with all its
// channels as float, in the file's channel order (OpenEXR sorts channels by
// name, so R, G, B come out as B, G, R; use read_exr_rgb for colour).
// `max_pixels` bounds width*height before allocation.
FloatImage read_exr(const std::string& path, long long max_pixels = kMaxImagePixels);

// Reads an EXR and returns its R, G, B channels interleaved (channel_names
// {"R","G","B"}). A file with other than exactly the channels R, G, B is
// refused unless `allow_luminance` and it has a single channel (Y or any one
// name), which is then copied to R, G and B.
FloatImage read_exr_rgb(const std::string& path, bool allow_luminance = false,
                        long long max_pixels = kMaxImagePixels);

// Writes float channels (any names; usually R, G, B) as a ZIP-compressed
// 32-bit float scanline EXR; `comment` goes into the standard comments
// attribute when not empty.
void write_exr(const std::string& path, const FloatImage& image, const std::string& comment = "");

// Radiance RGBE (.hdr / .pic): reads flat and run-length-encoded scanlines
// ("-Y H +X W" orientation only) into R, G, B floats; writes flat RGBE.
FloatImage read_hdr(const std::string& path, long long max_pixels = kMaxImagePixels);
void write_hdr(const std::string& path, const FloatImage& rgb);

// 8-bit sRGB PNG, 3 channels interleaved, row 0 on top.
void write_png_rgb8(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb);
std::vector<uint8_t> read_png_rgb8(const std::string& path, int& width, int& height);

// Version strings of the image libraries (recorded in manifests).
std::string openexr_version();
std::string libpng_version();

}  // namespace bf
