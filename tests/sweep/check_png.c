/* check_png FILE W H: exit 0 iff libpng reads FILE completely and it is W
 * pixels wide and at least H rows high (heat maps add a legend below). */
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char **argv) {
    if (argc != 4) {
        fprintf(stderr, "usage: check_png FILE W H\n");
        return 2;
    }
    png_image im;
    memset(&im, 0, sizeof im);
    im.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&im, argv[1])) {
        fprintf(stderr, "%s: %s\n", argv[1], im.message);
        return 1;
    }
    im.format = PNG_FORMAT_RGB;
    png_bytep buf = malloc(PNG_IMAGE_SIZE(im));
    if (!buf || !png_image_finish_read(&im, NULL, buf, 0, NULL)) {
        fprintf(stderr, "%s: %s\n", argv[1], im.message);
        return 1;
    }
    unsigned w = (unsigned)atoi(argv[2]), h = (unsigned)atoi(argv[3]);
    if (im.width != w || im.height < h) {
        fprintf(stderr, "%s: %ux%u, expected width %u and height >= %u\n", argv[1], im.width, im.height, w, h);
        return 1;
    }
    /* Not one flat colour: the picture has content. */
    size_t n = PNG_IMAGE_SIZE(im);
    int varied = 0;
    for (size_t i = 3; i < n && !varied; i++) varied = buf[i] != buf[i % 3];
    free(buf);
    if (!varied) {
        fprintf(stderr, "%s: a single flat colour\n", argv[1]);
        return 1;
    }
    printf("%s: ok %ux%u\n", argv[1], im.width, im.height);
    return 0;
}
