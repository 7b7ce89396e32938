/*
 * libodhs - minimal outside consumer, built by `make pkgconfig-test` against
 * the staged install using nothing but `pkg-config --cflags --libs odhs`
 * (and `--static`). Checks that the header and the linked library agree.
 */
#include <odhs.h>

#include <stdio.h>
#include <string.h>

int main(void)
{
    const char *rt = odhs_version_string();
    printf("libodhs run-time version %s, header version %s\n",
           rt ? rt : "(null)", ODHS_VERSION_STRING);
    if (rt == NULL || strcmp(rt, ODHS_VERSION_STRING) != 0) {
        fprintf(stderr, "pkgconfig_consumer: version mismatch\n");
        return 1;
    }
    if (odhs_version_number() != ODHS_VERSION_NUMBER) {
        fprintf(stderr, "pkgconfig_consumer: version number mismatch\n");
        return 1;
    }
    return 0;
}
