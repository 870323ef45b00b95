/* wv_api.c -- the function table lensmat-wave.so exports (wave_get_api), the only
 * symbol it exports (every other is hidden). */
#include <fftw3.h>
#include <gsl/gsl_version.h>
#include <stdio.h>
#include "wv_int.h"

static const char *version(void)
{
    static char v[160];
    if (!v[0]) snprintf(v, sizeof v, "lensmat wave engine (ABI 1), %s, GSL %s",
                        fftw_version, GSL_VERSION);
    return v;
}

static const wave_api api = {
    WAVE_ABI,
    version,
    wv_ctx_new,
    wv_ctx_free,
    wv_pupil_mask,
    wv_pupil_add_zernike,
    wv_zernike_nm,
    wv_zernike,
    wv_zernike_name,
    wv_zernike_fit,
    wv_psf,
    wv_energy,
    wv_mtf,
    wv_otf,
    wv_otf_dir,
    wv_mtf_diffraction,
    wv_resolution,
    wv_kirchhoff,
    wv_fraunhofer,
    wv_fraunhofer_ee,
    wv_jones,
    wv_fresnel,
    wv_film,
};

__attribute__((visibility("default"))) const wave_api *wave_get_api(int abi)
{
    return abi == WAVE_ABI ? &api : NULL;
}
