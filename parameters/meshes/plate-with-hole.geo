// A plate (0,2) x (0,1) with a circular hole of radius 0.2 around (1.4, 0.5),
// for parameters/own-scene.prm. Make the mesh with
//   gmsh -2 -format msh2 plate-with-hole.geo -o plate-with-hole.msh
// (-format msh4 works too; -clscale 0.5 halves the cell size).
h = 0.25;            // cell size on the outer boundary
h_hole = 0.08;       // cell size on the hole

Point(1) = {0, 0, 0, h};
Point(2) = {2, 0, 0, h};
Point(3) = {2, 1, 0, h};
Point(4) = {0, 1, 0, h};
Point(5) = {1.4, 0.5, 0, h_hole};
Point(6) = {1.6, 0.5, 0, h_hole};
Point(7) = {1.4, 0.7, 0, h_hole};
Point(8) = {1.2, 0.5, 0, h_hole};
Point(9) = {1.4, 0.3, 0, h_hole};

Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Circle(5) = {6, 5, 7};
Circle(6) = {7, 5, 8};
Circle(7) = {8, 5, 9};
Circle(8) = {9, 5, 6};

Curve Loop(1) = {1, 2, 3, 4};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(1) = {1, 2};

// One physical group for the boundary and one for the plate: membranes
// gives every boundary part the same data g and g2, whatever its tag.
Physical Curve(1) = {1, 2, 3, 4, 5, 6, 7, 8};
Physical Surface(1) = {1};
