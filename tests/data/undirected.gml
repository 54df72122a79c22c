graph [
  comment "Undirected path x - y - z; labels become the node names."
  node [ id 0 label "x" ]
  node [ id 1 label "y" ]
  node [ id 2 label "z" ]
  edge [ source 0 target 1 ]
  edge [ source 1 target 2 ]
]
