/* baseline.c -- the honest floor for a classic replay: a trivial C program that
 * reads all of stdin and writes a file of a given size.  Process start-up, reading
 * and writing, nothing else. */
#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv)
{
    char buf[4096];
    long size, n = 0;
    FILE *f;
    if (argc < 3) return 2;
    size = atol(argv[2]);
    while (fread(buf, 1, sizeof buf, stdin) > 0) n++;
    if (!(f = fopen(argv[1], "w"))) return 1;
    for (long i = 0; i < size; i++) fputc('x', f);
    printf("read %ld blocks\n", n);
    return fclose(f) != 0;
}
