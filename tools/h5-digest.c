/* Print one line per dataset of an HDF5 file: its path, type class and
 * size, dimensions and an FNV-1a 64-bit hash of its raw bytes (read in the
 * file's own type), and one line per attribute likewise. Used by
 * tools/compare-examples to compare HDF5 output bit for bit without the
 * object modification times HDF5 stores in the headers.
 *   h5cc -o build/h5-digest tools/h5-digest.c && build/h5-digest FILE.h5 */
#include <hdf5.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

static uint64_t fnv(const unsigned char *p, size_t n)
{
  uint64_t h = 1469598103934665603ULL;
  for (size_t i = 0; i < n; i++) {
    h ^= p[i];
    h *= 1099511628211ULL;
  }
  return h;
}

static void attributes(hid_t obj, const char *path)
{
  H5O_info_t info;
  if (H5Oget_info2(obj, &info, H5O_INFO_NUM_ATTRS) < 0) return;
  for (hsize_t i = 0; i < info.num_attrs; i++) {
    hid_t a = H5Aopen_by_idx(obj, ".", H5_INDEX_NAME, H5_ITER_INC, i, H5P_DEFAULT, H5P_DEFAULT);
    if (a < 0) continue;
    char name[256];
    H5Aget_name(a, sizeof name, name);
    hid_t t = H5Aget_type(a), s = H5Aget_space(a);
    hssize_t n = H5Sget_simple_extent_npoints(s);
    size_t size = H5Tget_size(t);
    unsigned char *buf = NULL;
    uint64_t h = 0;
    if (H5Tis_variable_str(t) <= 0 && n >= 0) {
      buf = calloc((size_t)n * size + 1, 1);
      if (buf && H5Aread(a, t, buf) >= 0) h = fnv(buf, (size_t)n * size);
    }
    printf("attr %s@%s class %d size %zu n %lld fnv %016llx\n", path, name, (int)H5Tget_class(t),
           size, (long long)n, (unsigned long long)h);
    free(buf);
    H5Tclose(t);
    H5Sclose(s);
    H5Aclose(a);
  }
}

static herr_t visit(hid_t root, const char *name, const H5O_info_t *info, void *data)
{
  (void)data;
  hid_t obj = H5Oopen(root, name, H5P_DEFAULT);
  if (obj < 0) return -1;
  attributes(obj, name);
  if (info->type == H5O_TYPE_DATASET) {
    hid_t t = H5Dget_type(obj), s = H5Dget_space(obj);
    int rank = H5Sget_simple_extent_ndims(s);
    hsize_t dims[32] = {0};
    H5Sget_simple_extent_dims(s, dims, NULL);
    hssize_t n = H5Sget_simple_extent_npoints(s);
    size_t size = H5Tget_size(t);
    unsigned char *buf = malloc((size_t)n * size + 1);
    uint64_t h = 0;
    if (buf && H5Dread(obj, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0) h = fnv(buf, (size_t)n * size);
    printf("data %s class %d size %zu dims", name, (int)H5Tget_class(t), size);
    for (int i = 0; i < rank; i++) printf(" %llu", (unsigned long long)dims[i]);
    printf(" fnv %016llx\n", (unsigned long long)h);
    free(buf);
    H5Tclose(t);
    H5Sclose(s);
  }
  H5Oclose(obj);
  return 0;
}

int main(int argc, char **argv)
{
  if (argc != 2) {
    fprintf(stderr, "usage: h5-digest FILE.h5\n");
    return 2;
  }
  hid_t f = H5Fopen(argv[1], H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return 1;
  herr_t status = H5Ovisit2(f, H5_INDEX_NAME, H5_ITER_INC, visit, NULL, H5O_INFO_BASIC);
  H5Fclose(f);
  return status < 0 ? 1 : 0;
}
