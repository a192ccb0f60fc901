#include "raytable/chunk_ini.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "povray/povray.h"

char *chunk_ini_absolute(const char *path)
{
    char cwd[4096];
    if (path[0] == '/' || !getcwd(cwd, sizeof cwd))
        return strdup(path);
    char *abs = malloc(strlen(cwd) + strlen(path) + 2);
    if (abs)
        sprintf(abs, "%s/%s", cwd, path);
    return abs;
}

static int ini_cannot_carry(const char *path, l2p_error *err)
{
    return l2p_fail(err, L2P_BAD_INPUT, path, 0, "POV-Ray's .ini cannot name this file (it has "
                    "a '\"', a control character or a byte beyond ASCII): choose another name");
}

int chunk_ini_check_prefix(const char *prefix, l2p_error *err)
{
    char *abs = chunk_ini_absolute(prefix);
    if (!abs)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    const int st = povray_ini_can_carry(abs) ? L2P_OK : ini_cannot_carry(abs, err);
    free(abs);
    return st;
}

void chunk_ini_as_render(FILE *fp, int film_width, int film_height)
{
    fprintf(fp, "; As render runs POV-Ray: a scene without gamma handling decoded as sRGB, and the\n"
                "; film's size, not the packed image's, as image_width and image_height.\n"
                "Display_Gamma=sRGB\nDeclare=image_width=%d\nDeclare=image_height=%d\n",
            film_width, film_height);
}

int chunk_ini_write(outfile *ini, const char *ini_path, const char *exr_path, int width,
                    long long height, int film_width, int film_height, l2p_error *err)
{
    char *exr = chunk_ini_absolute(exr_path);
    int st = !exr ? l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory")
             : !povray_ini_can_carry(exr) ? ini_cannot_carry(exr, err)
                                          : outfile_open(ini, ini_path, err);
    if (!st) {
        const char *quote = povray_ini_needs_quotes(exr) ? "\"" : "";
        fprintf(ini->fp,
                "; lens2pov: POV-Ray settings for the ray table beside this file.\n"
                "; Row 0 of the image repeats row 1 (POV-Ray 3.7.0.10, FS#254): one row more.\n"
                "; The whole picture (fractions), whatever crop a user's ini before this one set.\n"
                "Width=%d\nHeight=%lld\nStart_Row=0.0\nEnd_Row=1.0\nStart_Column=0.0\n"
                "End_Column=1.0\nAntialias=Off\nOutput_File_Type=E\nOutput_To_File=On\n"
                "Output_File_Name=%s%s%s\nDisplay=Off\n", width, height, quote, exr, quote);
        chunk_ini_as_render(ini->fp, film_width, film_height);
    }
    free(exr);
    return st ? st : outfile_finish(ini, err);
}
