// mpi_image_compare A B [MAX_CHANNEL_DIFF]: the regression metric of
// tests/common/image_compare.h (8-bit sRGB channels; default tolerance) between two
// images, for the shell-driven MPI tests; with MAX_CHANNEL_DIFF, also no channel of any
// pixel may differ by more (the seam test). Prints the figures; exit 0 when within.
#include <cstdio>
#include <cstdlib>

#include "core/render/image_io.h"
#include "tests/common/image_compare.h"

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: mpi_image_compare A B [MAX_CHANNEL_DIFF]\n");
        return 2;
    }
    try {
        const rtfact::Image a = rtfact::readImage(argv[1]), b = rtfact::readImage(argv[2]);
        if (a.width != b.width || a.height != b.height || a.channels != 4 || b.channels != 4) {
            std::printf("%s and %s: different sizes or not RGBA\n", argv[1], argv[2]);
            return 1;
        }
        const rtfact::test::ImageTolerance tol;
        const rtfact::test::ImageDiff d =
            rtfact::test::compareRGBA(a.pixels, b.pixels, a.width, a.height, tol.channelTolerance);
        const int maxDiff = argc > 3 ? std::atoi(argv[3]) : 255;
        std::printf("psnr=%.2f different_fraction=%.5f max_channel_diff=%d\n", d.psnr, d.differentFraction,
                    d.maxChannelDiff);
        return d.differentFraction <= tol.maxDifferentFraction && d.psnr >= tol.minPsnr && d.maxChannelDiff <= maxDiff
                   ? 0
                   : 1;
    } catch (const std::exception& e) {
        std::printf("%s\n", e.what());
        return 1;
    }
}
