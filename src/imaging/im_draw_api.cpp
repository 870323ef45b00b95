/* im_draw_api.cpp -- the pictures' table of entry points (im_draw_api, imaging.h),
 * handed to the module's imaging_get_api. */
#include "im_draw.hpp"

extern "C" {
int im_draw_layout(const im_layout *, const im_out *, im_layout_info *, char *, size_t);
int im_draw_spot(const im_spotdiag *, const im_out *, im_sd_info *, char *, size_t);
int im_draw_plot(const im_plot *, const im_out *, im_plot_info *, char *, size_t);
void im_draw_spot_stat(const im_sd_point *, int, int, im_sd_stat *);
int im_draw_map(const im_map *, const im_out *, im_map_info *, char *, size_t);
}

static const im_draw_api table = {im_draw_layout, im_draw_spot, im_draw_plot, im_draw_spot_stat,
                                  im_draw_map};

extern "C" const im_draw_api *im_draw_table(void) { return &table; }
