// One level of one file on screen: instanced unit cubes whose per-instance data is the
// cell's grid coordinates and colour, placed by the shader (cell + 0.5) * cellSize +
// offset, so a batch from the server goes to the GPU without building matrices. Levels
// of more than POINTS_ABOVE cells are drawn as one point per cell, sized as the cell
// would appear: 36 cube vertices per cell would not draw interactively. The slicing
// plane hides whole cells in the vertex shader.
import * as THREE from 'three';

const POINTS_ABOVE = 2_000_000;

const vertexShader = /* glsl */ `
attribute vec3 cell;
attribute vec3 colour;
uniform float cellSize;
uniform vec3 offset;
uniform vec3 sliceAxis;
uniform float sliceAt;
uniform float sliceOn;
varying vec3 vColour;
void main() {
  vec3 centre = offset + (cell + 0.5) * cellSize;
  if (sliceOn > 0.5 && dot(centre, sliceAxis) > sliceAt) {
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // outside the clip volume: the cell is not drawn
    vColour = vec3(0.0);
    return;
  }
  float light = 0.55 + 0.45 * max(dot(normal, normalize(vec3(0.35, 0.25, 0.9))), 0.0);
  vColour = colour * light;
  gl_Position = projectionMatrix * modelViewMatrix * vec4(centre + position * cellSize, 1.0);
}`;

const pointVertexShader = /* glsl */ `
attribute vec3 colour;
uniform float cellSize;
uniform vec3 offset;
uniform vec3 sliceAxis;
uniform float sliceAt;
uniform float sliceOn;
uniform float pointScale;
varying vec3 vColour;
void main() {
  vec3 centre = offset + (position + 0.5) * cellSize;  // position holds the cell
  if (sliceOn > 0.5 && dot(centre, sliceAxis) > sliceAt) {
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
    vColour = vec3(0.0);
    return;
  }
  vec4 eye = modelViewMatrix * vec4(centre, 1.0);
  gl_PointSize = clamp(cellSize * pointScale / max(-eye.z, 1e-6), 1.0, 64.0);
  vColour = colour;
  gl_Position = projectionMatrix * eye;
}`;

const fragmentShader = /* glsl */ `
varying vec3 vColour;
void main() { gl_FragColor = vec4(vColour, 1.0); }`;

const unitCube = new THREE.BoxGeometry(1, 1, 1);

export class VoxelLayer {
  // file: metadata; level: its level; offset: the file's origin minus the scene origin.
  // slice: the shared uniforms of the slicing plane and the point scale.
  constructor(file, level, offset, slice) {
    this.file = file;
    this.level = level;
    this.total = file.levels[level].cells;
    this.loaded = 0;
    this.cellSize = file.levels[level].cell_size;
    this.cells = new Float32Array(3 * this.total);
    this.colours = new Uint8Array(3 * this.total);
    this.classes = file.has_classes ? new Uint8Array(this.total) : null;
    this.stored = file.has_colours ? new Uint8Array(3 * this.total) : null;
    this.asPoints = this.total > POINTS_ABOVE;
    let geometry;
    if (this.asPoints) {
      geometry = new THREE.BufferGeometry();
      this.cellAttribute = new THREE.BufferAttribute(this.cells, 3);
      this.colourAttribute = new THREE.BufferAttribute(this.colours, 3, true);
      geometry.setAttribute('position', this.cellAttribute);
      geometry.setDrawRange(0, 0);
    } else {
      geometry = new THREE.InstancedBufferGeometry();
      // Copies (24 vertices): disposing a layer frees its buffers, which others must not share.
      geometry.index = unitCube.index.clone();
      geometry.setAttribute('position', unitCube.getAttribute('position').clone());
      geometry.setAttribute('normal', unitCube.getAttribute('normal').clone());
      this.cellAttribute = new THREE.InstancedBufferAttribute(this.cells, 3);
      this.colourAttribute = new THREE.InstancedBufferAttribute(this.colours, 3, true);
      geometry.setAttribute('cell', this.cellAttribute);
      geometry.instanceCount = 0;
    }
    geometry.setAttribute('colour', this.colourAttribute);
    this.material = new THREE.ShaderMaterial({
      vertexShader: this.asPoints ? pointVertexShader : vertexShader,
      fragmentShader,
      uniforms: {
        cellSize: { value: this.cellSize },
        offset: { value: new THREE.Vector3(...offset) },
        sliceAxis: slice.axis,
        sliceAt: slice.at,
        sliceOn: slice.on,
        pointScale: slice.pointScale,
      },
    });
    this.mesh = this.asPoints ? new THREE.Points(geometry, this.material) : new THREE.Mesh(geometry, this.material);
    this.mesh.frustumCulled = false;  // the geometry's bounds are one unit cube
  }

  // Appends a batch from fetchCells (batches arrive in order).
  append(batch, colourOf) {
    const at = batch.first;
    for (let i = 0; i < 3 * batch.count; ++i) this.cells[3 * at + i] = batch.coords[i];
    if (this.classes && batch.classes) this.classes.set(batch.classes, at);
    if (this.stored && batch.colours) this.stored.set(batch.colours, 3 * at);
    this.loaded = at + batch.count;
    this.recolour(colourOf, at, this.loaded);
    this.cellAttribute.needsUpdate = true;
    if (this.asPoints) this.mesh.geometry.setDrawRange(0, this.loaded);
    else this.mesh.geometry.instanceCount = this.loaded;
  }

  // colourOf(layer, i) -> [r, g, b] for cells [from, to).
  recolour(colourOf, from = 0, to = this.loaded) {
    for (let i = from; i < to; ++i) this.colours.set(colourOf(this, i), 3 * i);
    this.colourAttribute.needsUpdate = true;
  }

  // Frees the GPU buffers; the layer is not drawn again.
  dispose() {
    this.mesh.removeFromParent();
    this.mesh.geometry.dispose();
    this.material.dispose();
  }

  // The world z of cell i's centre, relative to the file's origin.
  height(i) {
    return (this.cells[3 * i + 2] + 0.5) * this.cellSize;
  }
}
