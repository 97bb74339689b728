// vola::io and vola::geo from the installed package, each linked alone (a user reading
// PCD files, a user naming CRSs): a PCD written here read back, and PROJ's name of a code.
#include <vola/geo/crs.hpp>
#include <vola/io/pcd.hpp>

#include <cstdio>
#include <fstream>
#include <string>

int main(int argc, char** argv) {
#ifdef VOLA_CONSUMER_IO
  const std::string path = std::string(argc > 1 ? argv[1] : ".") + "/points.pcd";
  std::ofstream(path) << "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\n"
                         "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n0 0 0\n1 2 3\n";
  const vola::PointCloud cloud = vola::io::read_pcd(path);
  std::printf("pcd points %zu\n", cloud.size());
  return cloud.size() == 2 && cloud.xyz[5] == 3.0 ? 0 : 1;
#else
  (void)argc;
  (void)argv;
  const vola::geo::CrsDescription utm = vola::geo::describe_crs("EPSG:32633");
  std::printf("crs %s\n", utm.name.c_str());
  return utm.name == "WGS 84 / UTM zone 33N" && utm.epsg == 32633u ? 0 : 1;
#endif
}
