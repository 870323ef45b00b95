# t_93_topo.sh -- the topography pipeline (src/topo, issue 19): its module exports one
# symbol and lensmat does not link it (it is loaded by --cornea-scan on first use).
check "lensmat-topo.so exports topo_get_api alone" sh -c \
    "test \"\$(nm -D --defined-only '$TOP/build/lib/lensmat-topo.so' | grep ' T ' | awk '{print \$3}')\" = topo_get_api"
check "lensmat links no engine module (topo, cornea, GSL)" sh -c \
    "! ldd '$TOP/lensmat' | grep -q -e lensmat- -e gsl"
