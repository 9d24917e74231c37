// Image I/O on OpenEXR and libpng: round trips keep orientation and values,
// Radiance .hdr flat and run-length scanlines decode, bad files are refused.
#include <sys/stat.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>

#include "factor/image_io.h"
#include "test_common.h"

using namespace bf;
using Catch::Matchers::Contains;

namespace {

// An asymmetric pattern: every pixel and channel distinct, so a transpose,
// a flip or a channel swap changes some value.
FloatImage pattern(int w, int h) {
  FloatImage img;
  img.width = w;
  img.height = h;
  img.channel_names = {"R", "G", "B"};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) img.pixels.push_back(float(1 + x + 100 * y) * (c == 0 ? 1.0f : c == 1 ? 0.5f : 0.25f));
  return img;
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

}  // namespace

TEST_CASE("image_io: EXR round trip keeps every pixel where it was (row 0 on top, x to the right)") {
  bf_test::TempDir d("image-io");
  const FloatImage img = pattern(5, 3);
  write_exr(d.file("a.exr"), img, "a comment");
  const ImageSize s = read_exr_size(d.file("a.exr"));
  CHECK(s.width == 5);
  CHECK(s.height == 3);
  const FloatImage back = read_exr_rgb(d.file("a.exr"));
  REQUIRE(back.width == 5);
  REQUIRE(back.height == 3);
  REQUIRE(back.pixels == img.pixels);
  // Pixel (x = 4, y = 0) is the top-right one: 1 + 4 = 5 in red.
  CHECK(back.pixels[(0 * 5 + 4) * 3 + 0] == 5.0f);
  // Pixel (x = 0, y = 2) is the bottom-left one: 1 + 200 = 201 in red, 50.25 in blue.
  CHECK(back.pixels[(2 * 5 + 0) * 3 + 0] == 201.0f);
  CHECK(back.pixels[(2 * 5 + 0) * 3 + 2] == 50.25f);
  // read_exr gives the channels in the file's (alphabetical) order.
  const FloatImage raw = read_exr(d.file("a.exr"));
  CHECK(raw.channel_names == std::vector<std::string>{"B", "G", "R"});
  CHECK(raw.pixels[0] == 0.25f);
}

TEST_CASE("image_io: EXR with other channels is refused naming them, a grey one is accepted where allowed") {
  bf_test::TempDir d("image-io");
  FloatImage two;
  two.width = two.height = 2;
  two.channel_names = {"R", "G"};
  two.pixels.assign(8, 1.0f);
  write_exr(d.file("rg.exr"), two);
  CHECK_THROWS_WITH(read_exr_rgb(d.file("rg.exr")), Contains("rg.exr") && Contains("expected 3 channels (R, G, B)") &&
                                                        Contains("found 2 (G, R)"));
  FloatImage grey;
  grey.width = grey.height = 2;
  grey.channel_names = {"Y"};
  grey.pixels = {1, 2, 3, 4};
  write_exr(d.file("y.exr"), grey);
  CHECK_THROWS_WITH(read_exr_rgb(d.file("y.exr")), Contains("found 1 (Y)"));
  const FloatImage g = read_exr_rgb(d.file("y.exr"), true);
  CHECK(g.pixels == std::vector<float>{1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4});
}

TEST_CASE("image_io: non-regular, missing, truncated and oversized files are refused with the path") {
  bf_test::TempDir d("image-io");
  CHECK_THROWS_WITH(read_exr(d.file("missing.exr")), Contains("missing.exr") && Contains("file not found"));
  CHECK_THROWS_WITH(read_exr("/dev/zero"), Contains("/dev/zero") && Contains("expected a regular file"));
  CHECK_THROWS_WITH(read_hdr("/dev/zero"), Contains("expected a regular file"));
  CHECK_THROWS_WITH(read_exr(d.path.string()), Contains("expected a regular file"));
  const std::string fifo = d.file("fifo.exr");
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  CHECK_THROWS_WITH(read_exr(fifo), Contains("expected a regular file"));  // would block if opened
  int w = 0, h = 0;
  CHECK_THROWS_WITH(read_png_rgb8(fifo, w, h), Contains("expected a regular file"));

  write_exr(d.file("big.exr"), pattern(64, 64));
  CHECK_THROWS_WITH(read_exr(d.file("big.exr"), 100), Contains("big.exr") && Contains("expected at most 100 pixels") &&
                                                         Contains("found 64x64"));
  // Truncated: the header survives, the pixel data does not.
  const std::string bytes = bf_test::slurp(d.file("big.exr"));
  write_bytes(d.file("cut.exr"), bytes.substr(0, bytes.size() / 2));
  CHECK_THROWS_WITH(read_exr(d.file("cut.exr")), Contains("cut.exr") && Contains("cannot read EXR image"));
  write_bytes(d.file("text.exr"), "not an image at all\n");
  CHECK_THROWS_WITH(read_exr(d.file("text.exr")), Contains("text.exr") && Contains("cannot read EXR image"));
}

TEST_CASE("image_io: Radiance .hdr round trip within RGBE precision and decoding of run-length scanlines") {
  bf_test::TempDir d("image-io");
  const FloatImage img = pattern(9, 4);
  write_hdr(d.file("a.hdr"), img);
  const FloatImage back = read_hdr(d.file("a.hdr"));
  REQUIRE(back.width == 9);
  REQUIRE(back.height == 4);
  for (size_t k = 0; k < img.pixels.size(); k += 3) {
    const float peak = std::max({img.pixels[k], img.pixels[k + 1], img.pixels[k + 2]});
    for (int c = 0; c < 3; ++c)  // 8-bit mantissa of the largest component: 1/256 of it, plus the half-step bias
      CHECK(std::abs(back.pixels[k + c] - img.pixels[k + c]) <= peak / 128.0f);
  }
  // One 8-pixel scanline in new-style RLE: red a run of 8 x 128, green 8 literal
  // values, blue a run of 0, exponent a run of 129 (2^1): red = (128.5/256) * 2 = 1.00390625.
  std::string rle = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 8\n";
  rle += std::string("\x02\x02\x00\x08", 4);
  rle += std::string("\x88\x80", 2);
  rle += std::string("\x08", 1) + std::string("\x00\x10\x20\x30\x40\x50\x60\x70", 8);
  rle += std::string("\x88\x00", 2);
  rle += std::string("\x88\x81", 2);
  write_bytes(d.file("rle.hdr"), rle);
  const FloatImage r = read_hdr(d.file("rle.hdr"));
  REQUIRE(r.width == 8);
  REQUIRE(r.height == 1);
  for (int x = 0; x < 8; ++x) {
    CHECK(r.pixels[3 * x + 0] == Approx(128.5 / 128.0));
    CHECK(r.pixels[3 * x + 1] == Approx((16 * x + 0.5) / 128.0));
    CHECK(r.pixels[3 * x + 2] == Approx(0.5 / 128.0));
  }
  // A run that overflows the scanline, a truncated file, a bad resolution line.
  std::string bad = rle;
  bad[bad.size() - 2] = char(0x89);
  write_bytes(d.file("over.hdr"), bad);
  CHECK_THROWS_WITH(read_hdr(d.file("over.hdr")), Contains("over.hdr") && Contains("scanline 0") && Contains("expected a run of 1..8 pixels"));
  write_bytes(d.file("cut.hdr"), rle.substr(0, rle.size() - 3));
  CHECK_THROWS_WITH(read_hdr(d.file("cut.hdr")), Contains("found end of file"));
  write_bytes(d.file("res.hdr"), "#?RADIANCE\n\n+Y 1 +X 8\n");
  CHECK_THROWS_WITH(read_hdr(d.file("res.hdr")), Contains("line 3") && Contains("expected a resolution"));
  write_bytes(d.file("huge.hdr"), "#?RADIANCE\n\n-Y 100000 +X 100000\n");
  CHECK_THROWS_WITH(read_hdr(d.file("huge.hdr")), Contains("expected at most") && Contains("found 100000x100000"));
  write_bytes(d.file("xyz.hdr"), "#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\nabcd");
  CHECK_THROWS_WITH(read_hdr(d.file("xyz.hdr")), Contains("line 2") && Contains("expected FORMAT=32-bit_rle_rgbe"));
}

TEST_CASE("image_io: PNG round trip keeps every byte in place") {
  bf_test::TempDir d("image-io");
  std::vector<uint8_t> px;
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 7; ++x)
      for (int c = 0; c < 3; ++c) px.push_back(uint8_t(x * 30 + y * 7 + c));
  write_png_rgb8(d.file("a.png"), 7, 3, px);
  int w = 0, h = 0;
  CHECK(read_png_rgb8(d.file("a.png"), w, h) == px);
  CHECK(w == 7);
  CHECK(h == 3);
  CHECK_THROWS_WITH(write_png_rgb8(d.file("b.png"), 7, 3, std::vector<uint8_t>(5)), Contains("expected 7x3x3 bytes"));
}
