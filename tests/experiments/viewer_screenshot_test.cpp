// report.html at three window sizes in headless Chromium: the viewer opened by
// report.html?viewer (the page above it hidden, unscrolled) is on screen and
// drawn at phone-ish, tall and wide sizes. Slow: three Chromium launches.
#include <cstdlib>
#include <set>

#include "experiments_helpers.h"
#include "factor/image_io.h"

using namespace bf;
using namespace bf_test;

TEST_CASE("viewer: report.html?viewer screenshots are not blank at 800x600 1400x1500 and 1920x1080", "[slow]") {
  const std::string browser = chromium_browser();
  INFO("chromium not installed (scripts/install-deps.sh installs it)");
  REQUIRE(!browser.empty());
  ScratchDir dir;
  const std::string cfg = write_text(dir / "shot.toml", R"(
[experiment]
name = "shot"
[[brdf]]
preset = "bluepaint"
[sampling]
kind = "grid"
resolution = 6
[scene]
size = 32
[[method]]
kind = "mccool"
texture_size = 8
)");
  REQUIRE(run_quiet(cfg, dir / "out").failed == 0);
  for (const auto& [w, h] : {std::pair{800, 600}, std::pair{1400, 1500}, std::pair{1920, 1080}}) {
    const std::string png = dir / ("shot-" + std::to_string(w) + ".png");
    const std::string cmd = chromium_command(browser, "--hide-scrollbars --window-size=" + std::to_string(w) + "," +
                                                          std::to_string(h) + " --screenshot=" + png + " 'file://" +
                                                          (dir / "out/report.html") + "?viewer' > " +
                                                          (dir / "chromium.log") + " 2>&1");
    INFO(w << "x" << h);
    REQUIRE(std::system(cmd.c_str()) == 0);
    int pw = 0, ph = 0;
    const std::vector<uint8_t> px = read_png_rgb8(png, pw, ph);
    CHECK(pw == w);
    CHECK(ph == h);
    // Not blank: many colours (the spheres' shading and the colour bars), and
    // the viewer's dark sphere backgrounds (0.16 grey, sRGB 0x6f... below
    // 0x80) on at least 2% of the window.
    std::set<uint32_t> colours;
    size_t dark = 0;
    for (size_t k = 0; k + 2 < px.size(); k += 3) {
      colours.insert(uint32_t(px[k]) << 16 | uint32_t(px[k + 1]) << 8 | px[k + 2]);
      dark += px[k] < 0x80 && px[k + 1] < 0x80 && px[k + 2] < 0x80;
    }
    INFO(colours.size() << " colours, " << dark << " dark pixels of " << size_t(w) * h);
    CHECK(colours.size() > 200);
    CHECK(dark > size_t(0.02 * w * h));
  }
}
