/* table.c -- every dialogue lensmat offers and the general options; see table.h.
 * A new dialogue registers here only: main, --help, the man page check and the
 * fuzzer take it from this table. */
#include <string.h>
#include "dialogues.h"
#include "table.h"

const lm_dialogue lm_dialogues[] = {
    {"--classic", "the original lens-entry dialogue (the default)", lm_classic,
     lm_classic_example, NULL, 1},
    {"--trace", "ray tracing: scene files, a lens's real fan, tessellation table", lm_trace,
     lm_trace_example, "trace", 0},
    {"--draw", "pictures: a lens file's layout with real rays, spot diagram, ray fan (PNG, SVG)",
     lm_draw, lm_draw_example, "imaging", 0},
    {"--rig", "the cornea rig: home, move, expose, scan (sim or libgpiod; 36-39)", lm_rig,
     lm_rig_example, "rig", 0},
    {"--thick", "thick lens: n1, R1, t, n, R2, n3 (sections 8-10, 21)", lm_thick,
     lm_thick_example, NULL, 0},
    {"--thin", "thin lens equation: f, do, di from the other two (57)", lm_thin,
     lm_thin_example, NULL, 0},
    {"--gauss", "Gauss's formula, one refracting surface (section 4)", lm_gauss,
     lm_gauss_example, NULL, 0},
    {"--pair", "two thin lenses t apart (section 56)", lm_pair, lm_pair_example, NULL, 0},
    {"--magnifier", "simple magnifier (sections 31.7-31.8)", lm_magnifier,
     lm_magnifier_example, NULL, 0},
    {"--microscope", "single-lens and compound microscopes (31.9-31.10, 58)", lm_microscope,
     lm_microscope_example, NULL, 0},
    {"--telescope", "astronomical, terrestrial, Galileo telescopes (31.11-31.13)",
     lm_telescope, lm_telescope_example, NULL, 0},
    {"--vision", "spectacle power for a near or far point (41, 57)", lm_vision,
     lm_vision_example, NULL, 0},
    {"--cornea", "corneal radius <-> power, measuring accuracy (section 37)", lm_cornea,
     lm_cornea_example, NULL, 0},
    {"--cornea-scan", "cornea measurement: rig scan, traced spots, frames, centroids, fit, Sim K (issue 12)", lm_cornea_scan, lm_cornea_scan_example, "cornea", 0},
    {"--fit", "lens matrix from measurements (lsq), cardinal or nodal points (14, 24, 26)",
     lm_fit, lm_fit_example, "fit", 0},
    {"--spot", "laser-spot centroids in a detector frame: file, raw, synthetic or a stream (36, 46)",
     lm_spot, lm_spot_example, "imaging", 0},
    {"--prescription", "run the classic dialogue from a prescription file (-i FILE)",
     lm_prescription, lm_prescription_example, NULL, 1},
    {"--to-prescription", "write a classic record or answers (-i FILE) as a prescription",
     lm_to_prescription, lm_to_prescription_example, NULL, 0},
    {"--colour", "per wavelength: glasses by name, focal lengths, colour, Abbe numbers",
     lm_colour, lm_colour_example, NULL, 0},
    {"--to-zmx", "write any lens file (-i FILE: .zmx, prescription, record) as OpticStudio .zmx",
     lm_to_zmx, lm_to_zmx_example, NULL, 0},
    {"--to-thickness", "write any lens file (-i FILE) as a prescription by thickness",
     lm_to_thickness, lm_to_thickness_example, NULL, 0},
    {"--pupil", "a lens file's pupils, chief rays, spots and fans of rays aimed at the stop",
     lm_pupil, lm_pupil_example, "trace", 0},
    {"--beam", "Gaussian beam: waist, M^2, through lenses and surfaces (ABCD; section 46)",
     lm_beam, lm_beam_example, NULL, 0},
    {"--optimise", "damped least squares on a lens file's vary/target lines: the optimised prescription",
     lm_optimise, lm_optimise_example, "design", 0},
    {"--tolerance", "a lens file's tolerances: sensitivities, Monte Carlo of built lenses, yield",
     lm_tolerance, lm_tolerance_example, "design", 0},
    {"--wave", "wave optics of a lens file: wavefront, Zernike, PSF, Strehl, EE, MTF (42-45)",
     lm_wave, lm_wave_example, "wave", 0},
    {"--polar", "polarization and thin films: Jones calculus, Fresnel and TIR phases, coatings (40, 67-71)",
     lm_polar, lm_polar_example, "wave", 0},
};
const size_t lm_ndialogues = sizeof lm_dialogues / sizeof lm_dialogues[0];

const lm_option lm_options[] = {
    {"--original", NULL, NULL},
    {"--input", "-i", "F"},
    {"--example", NULL, NULL},
    {"--help", "-h", NULL},
    {"--version", NULL, NULL},
};
const size_t lm_noptions = sizeof lm_options / sizeof lm_options[0];

const lm_dialogue *lm_find_dialogue(const char *option)
{
    for (size_t i = 0; i < lm_ndialogues; i++)
        if (!strcmp(option, lm_dialogues[i].option)) return &lm_dialogues[i];
    return NULL;
}

int lm_whole_output(const lm_dialogue *d)
{
    return d->run == lm_to_zmx || d->run == lm_to_thickness || d->run == lm_to_prescription;
}
