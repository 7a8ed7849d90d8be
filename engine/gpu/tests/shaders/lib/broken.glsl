// Line 2 below has an undeclared identifier.
vec3 broken() { return undeclared_thing; }
