// Parametric aortic root with a closed trileaflet valve (issue 6): the wall (fixed particles), three leaflets
// (separate elastic bodies, clamped along their attachment to the wall) and the blood inside.
//
// Geometry, in the root's frame: axis +y, annulus (basal ring) plane y = 0 through `base`; polar angle theta
// about +y by the right-hand rule, theta = 0 along +x, so a point is base + (r cos theta, y, -r sin theta).
// s in [0, 1] runs across one sinus / leaflet from commissure k to commissure k+1.
//
//  * Lumen radius R(y, theta). Below the annulus (the LV outflow tract) R = annulus_radius. Between the
//  annulus
//    and the commissures the root is a truncated cone Rc(y) from annulus_radius to commissure_radius,
//    continued at commissure_radius up to the sinotubular junction (STJ) and then blended (smoothstep over
//    one commissure radius) into the ascending aorta. Each sinus of Valsalva bulges out of this cone *above*
//    its leaflet's attachment line and below the STJ:
//        R = Rc(y) + A sin^2(pi s) sin(pi (y - y_att(s)) / (H_stj - y_att(s))),
//    A chosen so that the largest radius, mid-sinus at half the STJ height, is sinus_radius. So R =
//    commissure radius at the commissures, the sinus radius mid-sinus, and below the attachment line (the
//    interleaflet triangles) the wall is the plain cone. With sinuses = false, A = 0 (a graft; a straight
//    tube when the annulus, commissure and aorta radii are equal).
//  * Attachment line of each leaflet (the crown between two commissures), on the cone:
//        y_att(s) = commissure_height cos^2(pi s),  r = Rc(y_att(s)),
//    at the annulus plane mid-sinus (r = annulus_radius), at the commissure height at both commissures.
//  * Closed leaflet, rho in [0, 1] from the centre to the attachment line:
//        (x, z) = (1 - rho) apex + rho attachment point(s),
//        y = y_c + (commissure_height - y_c) rho + (y_att(s) - commissure_height) rho^1.5
//            - S sin(pi rho) (1 - cos^4(pi s)).
//    At s = 0 and s = 1 this is the free edge, a straight line from the commissure (commissure_radius,
//    commissure_height) to the coaptation point (centre, y_c); y_c follows from the free-edge length Lf:
//    (Lf / 2)^2 = commissure_radius^2 + (commissure_height - y_c)^2. The three leaflets meet along the three
//    radial planes of the commissures. The attachment's drop fades towards the centre (rho^1.5) and the belly
//    sags by S (towards the ventricle), S solved so that the mid-line (s = 1/2), nadir to centre, is
//    leaflet_height long; the sag's profile 1 - cos^4 is level at the free edges and flat mid-leaflet. Both
//    s-profiles have zero slope at s = 0, 1, so neighbouring leaflets meet edge to edge with parallel
//    normals. For particles the surface is inset by dx/2 from the coaptation planes: the apex sits on the
//    sector's bisector dx/2 from both planes, and the attachment angles run over the sector less dx/2 (at the
//    commissure radius) at either end, so each free edge runs parallel to its plane at dx/2 and the
//    neighbouring leaflets' particles face each other dx apart (a closed valve with a gap of one spacing).
//  * Leaflet particles: a structured sheet. Rows run parallel to the attachment line, equally spaced by arc
//    length along each meridian (s = const), the first row dx/2 from the attachment, the last the apex;
//    along a row the points are equally spaced by arc length (about dx). Each point is repeated
//    leaflet_layers times along the surface normal, centred on the surface (thickness = layers dx); where the
//    sheet is folded tighter than its thickness, offset points closer than 0.6 dx to one already placed are
//    left out. Points nearer than 0.45 dx to a neighbour's sector or 0.4 dx to the lumen surface are left out
//    too, so leaflets never overlap each other or the wall (>= 0.9 dx between bodies).
//  * Mirror leaflets (leaflet_shape "mirror"): leaflet k's attachment is the cut of the plane P_k through its
//    two commissures (commissure_radius, commissure_height) and its nadir (annulus_radius, y = 0, mid-sector)
//    with the plain cone Rc(y); the sinus bulge starts there instead of at the cos^2 crown. The open leaflet
//    is the cone's surface above P_k, the closed one its reflection across P_k: the same (rho, s) projection
//    as above, with y such that the point reflected across P_k lies on the cone (bisection). Bending without
//    stretch keeps a clamped curve's geodesic curvature, so along a fixed curve a sheet can only take its
//    tangent plane or that plane's mirror image across the curve's osculating plane (do Carmo 1976, sect.
//    4-4): the open and the closed leaflet are such a pair, so this leaflet opens by bending alone. Free edge
//    and mid-line lengths follow from the root (27.4 and 19.3 mm with the defaults); leaflet_free_edge and
//    leaflet_height are not used.
//  * Clamp: leaflet particles within dx of the lumen surface (normal distance, see normal_scale; the first
//    row) are flagged clamped. Two rows also held the leaflet's slope, and the opening sheet folded beside
//    them.
//  * Commissure posts (shell mirror leaflets; commissure_post, default 5 mm, 0 = none): just below each
//    commissure the two leaflets' free edges run up to the wall dx apart and, as the valve opens, the
//    orifice's corner there is a wedge narrower than dx that the blood cannot resolve. In a real root the
//    tissue is continuous there (the cusps attach side by side to the wall at the commissure, above the
//    interleaflet triangle), so within commissure_post of the commissure's top point (commissure_radius,
//    commissure_height) the leaflet particles are clamped and the space between the two sheets (on the
//    coaptation plane between their free edges, and below both sheets) is wall particles (post_points);
//    the blood leaves that space.
//  * Lunula (shell leaflets, lunula_height h > 0): each leaflet's free margin stands above the closure line,
//    as in a real valve, whose cusps overlap there by the coaptation height. Columns of particles dx apart
//    rise straight up from the sheet's free-edge particles, in the plane dx/2 inside the sector beside each
//    coaptation plane (where the free edge runs), h (1 - (r / r_l)^2) high at radius r (r_l: lunula_radius,
//    by default commissure_radius; none beyond), with the normal across the band into the sector (the aortic
//    side); the sheet itself is unchanged.
//  * Wall: rings of particles at y levels (spaced dx, closer where the sinus wall is steep, so spacing along
//    the wall stays <= dx), each ring wall_layers deep, layer j at R + (j + 1/2) dx (scaled by the wall's
//    slope so the layers are dx apart along the normal); rings and layers staggered by half a spacing; ends
//    open. The mesh is the lumen surface R(y, theta), closed around the axis, normals towards the axis.
//  * Blood: lattice points (spacing dx, aligned with base) at least dx/2 inside the lumen surface (along its
//    normal) and 0.9 dx from every leaflet particle, from the bottom of the LVOT to the top of the aorta.
//
//  * Surgical geometry (issue 19 item 1, valve-sparing root replacement by reimplantation, David & Feindel
//    1992, J. Thorac. Cardiovasc. Surg. 103:617-622: the root is replaced by a tube graft sewn below the
//    annulus, the commissures resuspended inside it, the patient's cusps kept). surgical_root() rewrites the
//    parameters before anything is built: with graft_diameter > 0 the commissure and STJ radius are
//    graft_diameter / 2 (the aorta too unless aorta_radius is set; the annulus and the LVOT keep
//    annulus_radius, the cone runs from it to the graft's radius: set annulus_radius to the graft's radius
//    for a cylinder); a straight graft has no sinuses, a neo_sinus graft the sinus bulge above with
//    A = neo_sinus_bulge (sinus_radius = cone radius at half the STJ height + bulge). stj_diameter (native
//    roots) widens or narrows the wall linearly from the commissure radius at commissure_height to
//    stj_diameter / 2 at stj_height; the aorta then starts from it. Commissure height and position are the
//    existing commissure_height and commissure_angles (one commissure rotated by delta: sinus arcs 120 +
//    delta, 120 - delta, 120). Fixed cusps: Labrosse leaflets are built from leaflet_free_edge and
//    leaflet_height in any root; mirror leaflets have one free parameter, mirror_tilt, which is solved
//    (bisection on [0, 30] degrees, outward) so that the free edge is leaflet_free_edge long; their geometric
//    height then follows the root (geometric_height() says how far).
//
// All parts of one root must share the body transforms (rotate, translate); they rotate about `base`.
//
// Defaults (sim/scene.hpp AorticRootParams): Labrosse, Beller, Robicsek & Thubrikar 2006, "Geometric modeling
// of functional trileaflet aortic valves: development and clinical applications", J. Biomech. 39:2665-2672:
// annulus radius 13 mm, commissure radius 12 mm, commissure height 16.8 mm, free edge 30 mm, leaflet height
// 17 mm. Sinus radius 1.4 x annulus radius = 18.2 mm: the middle of the 1.3-1.5 band of sinus to annulus
// ratios of pressurised human roots that issue 6 quotes (Swanson & Clark 1974, "Dimensions and geometric
// relationships of the human aortic valve as a function of pressure", Circ. Res. 35:871-882; the paper's
// tables were not at hand here, so the ratio is taken as quoted).
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "geometry/shapes.hpp"
#include "scene.hpp"

namespace aortasph {

// A parameter that makes the geometry impossible, and why (the scene loader turns this into an error at the
// parameter's JSON path).
struct AorticRootError {
  std::string param;
  std::string message;
};
std::optional<AorticRootError> check_aortic_root(const AorticRootParams& p, double dx);

// The parameters with the surgical keys applied (see the header comment): a native root's come back as they
// are. AorticRoot applies it to the parameters it is given (params() returns the result; with fixed mirror
// cusps that is a root with the solved mirror_tilt and fixed_cusps false, so it is not solved again).
AorticRootParams surgical_root(const AorticRootParams& p);

// The particles (and for the wall, the lumen surface mesh) of one part, in world coordinates before the
// body's own rotate/translate. Leaflets carry `clamped` flags. Deterministic order.
ShapeSample sample_aortic_root(const AorticRootParams& p, AorticPart part, int leaflet, double dx);

// Derived geometry, for tests, probes and scene authors.
class AorticRoot {
 public:
  explicit AorticRoot(const AorticRootParams& p);

  const AorticRootParams& params() const { return p_; }
  // Lumen radius at height y above the annulus plane and polar angle theta [rad].
  double lumen_radius(double y, double theta) const;
  // Radial distance per unit distance along the lumen surface's normal at (y, theta): sqrt(1 + R_y^2 +
  // (R_theta / R)^2). Radial gaps divided by it are (to first order) normal distances to the wall.
  double normal_scale(double y, double theta) const;
  // Radius of the plain cone (no sinus) at height y.
  double cone_radius(double y) const;
  // Leaflet k's sector: first commissure angle [rad] and its width [rad].
  double sector_start(int k) const { return phi_[k]; }
  double sector_width(int k) const { return dphi_[k]; }
  // Sector index and fraction s in [0, 1) of a polar angle.
  int sector_of(double theta, double& s) const;
  double attachment_height(double s) const { return attachment_height(0, s); }
  double attachment_height(int k, double s) const;
  double coaptation_height() const { return y_c_; }  // centre of the closed valve, above the annulus
  double belly_sag() const { return sag_; }
  // The closed leaflets' free edge (commissure -> centre -> next commissure) and geometric height (the
  // mid-line, annulus nadir -> centre), on the surface without the dx/2 inset, averaged over the three.
  double free_edge_length() const;
  double geometric_height() const;
  // Closed leaflet surface point (root frame, relative to base) at (rho, s) of leaflet k; with inset > 0, the
  // surface pulled in by that distance from the two coaptation planes (see the header comment).
  Vec3 leaflet_surface(int k, double rho, double s, double inset = 0.0) const;
  // Lowest point of the closed leaflets above the annulus plane (negative: below it).
  double leaflet_lowest() const;
  // Radius inside which the closed leaflets' projection covers the lumen: the narrowest attachment radius,
  // min(annulus_radius, commissure_radius). Use it as the disc radius of orifice_area for this valve.
  double orifice_radius() const;
  // Lumen cross-section area at the annulus plane.
  double annulus_area() const;

  std::vector<Vec3> wall_points(double dx, SurfaceMesh* mesh) const;
  std::vector<Vec3> leaflet_points(int k, double dx, std::vector<uint8_t>* clamped) const;
  // Shell leaflet k (issue 16; params().shell_leaflets): ONE layer of particles on the mid-surface the
  // volumetric layers are centred on (the rows and points of leaflet_points, the same margins from the
  // neighbouring sectors and the wall), with per point the unit normal (one orientation over the leaflet,
  // from the ventricular to the aortic side: +y mid-belly), the surface element it stands for (areas sum to
  // the mid-surface's area; a point left out near the wall hands its area on) and the clamp (the first row,
  // at the attachment line, and what lies within 0.6 dx of the lumen surface; the sheet keeps 0.1 dx inside
  // it).
  ShapeSample leaflet_shell(int k, double dx) const;
  std::vector<Vec3> blood_points(double dx) const;
  // Commissure posts (shell mirror leaflets, params().commissure_post_length() > 0): wall particles
  // (appended to wall_points) filling, within that distance of each commissure's top point
  // (commissure_point), the narrow space between the two leaflets that meet there: on the coaptation plane
  // between their free edges and below both sheets, inside the lumen (the grid is in the .cpp). The blood
  // leaves that region (in_post) and 0.75 dx round the post's particles.
  std::vector<Vec3> post_points(double dx) const;
  // Commissure c's top point (commissure_radius, commissure_height, angle c), root frame relative to base.
  Vec3 commissure_point(int c) const;
  // Whether x (root frame, relative to base) is in a commissure post's region (see post_points).
  bool in_post(const Vec3& x) const;

  Vec3 to_world(double r, double theta, double y) const;

 private:
  double midline_length(double sag) const;
  ShapeSample leaflet_shell_uncached(int k, double dx) const;
  // Whether x (root frame) is within `reach` of a commissure's top point (the commissure posts' clamp).
  bool near_commissure(const Vec3& x, double reach) const;
  // Appends leaflet k's lunula (lunula_height > 0) to its sheet `out`: columns dx apart straight up from the
  // free-edge particles (row_of: leaflet_mid_surface's rows; kept: the mid-surface points that out holds, in
  // order).
  void add_lunula(int k, double dx, const std::vector<int>& row_of, const std::vector<std::size_t>& kept,
                  ShapeSample& out) const;
  // The blood lattice (see blood_points), less the commissure posts' region and 0.75 dx round their
  // particles.
  std::vector<Vec3> blood_lattice(double dx) const;
  // Leaflet k's mid-surface points (root frame, relative to base), row by row, with the unit normals
  // d_rho x d_s (not oriented) and, if asked, the surface element of each point. With `embedded`, a row -1
  // half a spacing beyond the attachment line, into the wall (shell leaflets: see leaflet_shell).
  void leaflet_mid_surface(int k, double dx, std::vector<Vec3>& mids, std::vector<Vec3>& normals,
                           std::vector<double>* areas, std::vector<int>* row_of, bool embedded = false) const;
  double bump(int k, double s, double y) const;
  // Mirror leaflets: signed distance of x (root frame) from leaflet k's attachment plane (positive on the
  // aortic side), the reflection across it, and the closed surface's height above (x, z).
  double plane_side(int k, const Vec3& x) const;
  Vec3 reflect(int k, const Vec3& x) const;
  double mirror_height(int k, double x, double z) const;
  // Mirror leaflets: radius of leaflet k's open surface at height y and sector fraction s.
  double open_radius(int k, double y, double s) const;

  AorticRootParams p_;
  double phi_[3], dphi_[3];
  double y_c_ = 0.0, sag_ = 0.0, bulge_ = 0.0;
  Vec3 plane_n_[3], plane_p_[3];       // mirror leaflets: attachment planes (unit normal, a point)
  std::vector<double> attachment_[3];  // mirror leaflets: attachment height at s = i / (size - 1)
  double lean_ = 0.0;                  // mirror leaflets: dr/dy of the open surface's lines (open_radius)
  // leaflet_shell by (k, dx): the wall (the embedded rows, the posts) and the blood (their gaps) each ask for
  // the three sheets, which are costly to sample (mirror leaflets: bisections per surface point).
  struct ShellCache {
    std::mutex m;
    std::map<std::pair<int, double>, ShapeSample> sheets;
  };
  std::shared_ptr<ShellCache> shell_cache_ = std::make_shared<ShellCache>();
};

// Thin-leaflet scaling. A real leaflet is about t = 0.4 mm thick; the particle leaflet is layers x dx thick
// (>= 3 layers), so it is far thicker. Plate bending stiffness is D = E t^3 / (12 (1 - nu^2)); with the same
// Poisson ratio, the model leaflet bends like the real one when E_model t_model^3 = E_real t_real^3:
//     E_model = E_real (t_real / t_model)^3.
// Example (real E = 2 MPa, t = 0.4 mm, nu = 0.45): 3 layers at dx = 1 mm (t = 3 mm): 4.74 kPa; at
// dx = 0.5 mm (1.5 mm): 37.9 kPa. In-plane (membrane) stiffness E t is then (t_real / t_model)^2 too soft;
// the mass per area, if the density is kept (1100 kg/m^3), is t_model / t_real too high.
double bending_equivalent_modulus(double real_youngs_modulus, double real_thickness, double model_thickness);

}  // namespace aortasph
